// Finding the object in a scene before classifying it (issue 23, point 3): the floor and
// walls are removed as dominant axis-aligned planes at the scene's bounds, the rest is
// split into connected components (vola::analysis), one is chosen as the object, turned
// to its footprint's axes and resampled as clean objects are given to the classifier
// (longest extent spanning the 64^3 grid, centred). Nothing here knows how the rooms of
// `vola dataset --background` are generated: the rules below are the whole method.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "vola/learn/dataset.hpp"
#include "vola/tree.hpp"

namespace vola::learn {

class Classifier;

struct SegmentOptions {
  // A layer of voxels at the scene's bounding box (a plane x = c, y = c or z = c) belongs
  // to a floor, wall or ceiling when at least this share of the box's cross-section
  // there is occupied. Layers are peeled from each of the six faces inward while they
  // pass, up to `max_plane_layers` deep (a thick or slightly tilted scanned floor is
  // several layers).
  double plane_fill = 0.5;
  int max_plane_layers = 4;
  // Components whose bounding boxes come within this many empty voxels of each other
  // are pieces of one thing (a thin bar voxelised into fragments).
  int join_gap = 0;
  // Pieces smaller than this are noise (scan speckle, the rim of a removed wall).
  std::uint64_t min_voxels = 16;
  // classify_segmented: keep the most confident of the orientations (false) or average
  // their probabilities (true).
  bool average_orientations = false;
};

// One removed plane: `layers` layers of axis `axis` (0 x, 1 y, 2 z) starting at
// coordinate `first` and going inward (up from the minimum face, down from the maximum).
struct RemovedPlane {
  int axis = 0;
  bool at_max = false;
  std::uint32_t first = 0;
  int layers = 0;
  std::uint64_t voxels = 0;
};

// The scene without its bounding planes: every removed layer cut off with
// analysis::crop (the box that remains), and the planes it removed.
struct PlaneRemoval {
  Tree rest;
  Voxel min, max;  // the box kept (inclusive); min > max on an axis when nothing is kept
  std::vector<RemovedPlane> planes;
};
PlaneRemoval remove_bounding_planes(const Tree& scene, const SegmentOptions& options = {});

struct Segmentation {
  PlaneRemoval removal;
  std::size_t components = 0;  // pieces of the rest with at least min_voxels voxels
  // The rest's 26-connected components are grouped into pieces (boxes within join_gap
  // empty voxels of each other). The object: the piece with the largest bounding box
  // (by volume; ties: more voxels, then nearest the scene's centre in x and y), joined
  // by every other piece whose xy box overlaps its own (parts of the same object, such
  // as a table top over separate legs). Empty when no piece is left.
  Tree object;
  Voxel min, max;              // the object's bounds, in the scene's voxels
  double footprint_angle = 0;  // radians in [0, pi/2): the turn about z that makes its
                               // footprint's minimum-area rectangle axis-aligned
  bool found() const noexcept { return !object.empty(); }
};
Segmentation segment_object(const Tree& scene, const SegmentOptions& options = {});

// The object as a clean sample: turned by -footprint_angle about z, scaled (the same
// factor on every axis) so that its longest extent spans `kSceneSide` voxels, centred
// on every axis, each output voxel sampled from the object voxel its centre falls in.
// A 64^3 tree of depth kSceneDepth, like clean_scene's. Empty when the object is.
Tree normalise_object(const Tree& object, double footprint_angle);

// Segments `scene`, normalises the object, and classifies it with `classifier` (a model
// of clean objects) in `votes` orientations, the normalised object turned about z by
// 360 * k / votes degrees. The footprint's axes leave four candidate orientations (votes
// 4, the default, are exactly its quarter turns): for a model trained on aligned objects
// the most confident vote is kept; a model trained over the full circle averages them
// (SegmentOptions::average_orientations).
struct SegmentedClassification {
  Segmentation segmentation;
  std::array<float, kClassCount> probabilities{};  // all zero when nothing was found
  int vote = 0;                                    // the vote kept (0 when averaged)
};
std::vector<SegmentedClassification> classify_segmented(const Classifier& classifier,
                                                        std::span<const Tree* const> scenes,
                                                        const SegmentOptions& options = {}, int votes = 4);

}  // namespace vola::learn
