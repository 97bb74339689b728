// Ground classification by the Simple Morphological Filter (SMRF: Pingel, Clarke and
// McBride, "An improved simple morphological filter for the terrain classification of
// airborne LIDAR data", ISPRS J. Photogramm. 77, 2013), written from the paper:
//
//  1. the minimum surface: the lowest candidate point of each cell (cell size `cell`);
//  2. low outliers: cells below their neighbours that no neighbour continues in height
//     (unsupported: scattered echoes at random depths), then cells whose minimum is a
//     pit far below its neighbours (the same progressive opening run on the negated
//     surface, window kLowOutlierWindow, slope kLowOutlierSlope), are emptied, so that
//     a stray point below the ground cannot drag the surface down;
//  3. empty cells filled (inpainting: a push-pull pyramid, then Laplace smoothing);
//  4. progressive morphological opening with a disk of radius 1, 2, ... up to
//     window / cell cells: a cell is an object when one opening lowers it by more than
//     slope x radius x cell;
//  5. the provisional ground surface: the minimum surface without empty, outlier and
//     object cells, filled again; its slope (gradient magnitude) per cell;
//  6. a point is ground when |z - surface(x, y)| <= threshold + scalar x slope, with the
//     surface interpolated bilinearly at the point.
//
// As PDAL's filters.smrf does by default, only last returns (and single ones) can be
// ground, and points classified noise (7 low, 18 high) are left out of the surface and
// never ground. Overlap points (class 12 of LAS 1.1-1.3, marked by the survey to be left
// out of its products) help to find the surface but keep their class. Parameters are metres whatever the data's units (Units converts).
#pragma once

#include <span>
#include <vector>

#include "vola/builder.hpp"
#include "vola/filters/units.hpp"

namespace vola::filters {

struct SmrfOptions {
  double cell = 1.0;        // metres
  double slope = 0.15;      // rise over run
  double window = 18.0;     // metres: the largest opening's radius
  double threshold = 0.5;   // metres
  double scalar = 1.25;     // metres per unit of slope
  bool last_returns_only = true;
  // Throws OptionError naming the member out of range.
  void check() const;
};

// The low-outlier pass's window (metres) and slope: pits deeper than 5 m per metre of
// radius within 5 m are not terrain (real ditches and banks are far gentler).
inline constexpr double kLowOutlierWindow = 5.0;
inline constexpr double kLowOutlierSlope = 5.0;
// Pits that continue one another (within kLowOutlierWindow metres, heights within
// kPitDepth + kPitSlope x distance) across more than kPitNetworkExtent metres are ground
// seen through gaps in a canopy, not a cluster of echoes: they are kept.
inline constexpr double kPitNetworkExtent = 4.0 * kLowOutlierWindow;
// Before it, a cell is an unsupported low when some filled cell within kSupportRadius
// metres lies more than kPitDepth + kPitSlope x distance above it and fewer than two lie
// within that height of it; repeated up to kSupportPasses times.
inline constexpr double kSupportRadius = 3.0;
inline constexpr double kPitDepth = 1.0;
inline constexpr double kPitSlope = 1.0;
inline constexpr int kSupportPasses = 4;
// Where fewer filled cells than this lie within kSupportRadius, a cell is judged against
// this many nearest filled cells instead, however far (thinned surveys, data edges).
inline constexpr std::size_t kSparseNeighbours = 8;
// After the opening, patches of the ground surface that stand on walls above the rest
// are roofs wider than the window: measured cells that see each other across at most
// kLinkRadius metres (of empty cells) belong to one patch when they rise by at most
// kLinkRise + kLinkSlope x distance; a flat patch that is the upper side of most of its
// walls with patches of at least kMinBaseArea square metres (that it does not enclose)
// is not ground.
inline constexpr double kLinkRadius = 20.0;
inline constexpr double kLinkRise = 3.0;
inline constexpr double kLinkSlope = 0.5;
inline constexpr double kMinBaseArea = 16.0;
// The slope in the ground tolerance (threshold + scalar x slope) is taken between cells
// kSlopeBaseline metres to each side, not between neighbouring cells as the paper does.
inline constexpr double kSlopeBaseline = 3.0;

// Ground flags for points xyz (x y z triples); candidate[i] false leaves point i out of
// the surface and not ground. Throws InvalidArgument when the grid would pass 2^28 cells
// (a larger cell or a crop first).
std::vector<bool> smrf_ground(std::span<const double> xyz, const std::vector<bool>& candidate,
                              const SmrfOptions& options, const Units& units);

// On a cloud: classification 2 on ground points, 1 on the others (the column is added
// when missing), noise (7, 18) and overlap (12) kept. Returns the number of ground points.
std::size_t classify_ground(PointCloud& cloud, const SmrfOptions& options, const Units& units);

}  // namespace vola::filters
