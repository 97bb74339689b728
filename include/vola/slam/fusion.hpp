// KinectFusion over a brick TSDF store (tsdf_store.hpp): per frame, bilateral filter and
// a 3-level vertex/normal pyramid, projective point-to-plane ICP against the model
// raycast from the map at the previous pose (coarse to fine), TSDF integration of the
// filtered depth at the tracked pose into the bricks the frame's truncation band touches,
// and a new model raycast. Fusion<SparseTsdfStore> and Fusion<DenseTsdfStore> are the
// same code; only where the voxels live differs.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "vola/slam/features.hpp"
#include "vola/slam/image.hpp"
#include "vola/slam/loop_closure.hpp"
#include "vola/slam/preprocess.hpp"
#include "vola/slam/sequence.hpp"
#include "vola/slam/tsdf_store.hpp"

namespace vola::slam {

inline constexpr int kPyramidLevels = 3;

struct FusionParams {
  double voxel_size = 0.01;        // metres
  double truncation = 0.04;        // metres; the TSDF is clamped to +-1 beyond it
  float max_weight = 64.0f;        // running-average window of the integration
  double min_depth = 0.2, max_depth = 5.0;  // measurements outside are ignored
  int bilateral_radius = 3;
  double bilateral_sigma_space = 4.5;  // pixels
  double bilateral_sigma_depth = 0.03;  // metres
  std::array<int, kPyramidLevels> icp_iterations{10, 5, 4};  // level 0 (full size) .. 2
  double icp_max_distance = 0.1;       // metres between associated points
  double icp_max_angle_degrees = 20;   // between associated normals
  // Constant-velocity motion prior where the depth says (almost) nothing. The prediction
  // is the previous pose moved by the last tracked frame-to-frame motion; in each ICP
  // solve, every eigen-direction of the 6x6 normal matrix whose eigenvalue is below
  // motion_prior times the largest is raised to that floor by a prior pulling towards
  // the prediction. Well-observed directions are left to the data (their eigenvalues are
  // above the floor); where point-to-plane ICP cannot observe a motion (a flat wall and
  // a sofa give no normal along the wall, so sliding along it is free) the prediction
  // decides instead of noise. No prior until a frame-to-frame motion has been tracked
  // (the second frame, the first after a lost one). 0 disables it (KinectFusion's tracker).
  double motion_prior = 1e-2;
  // A frame whose ICP update exceeds these (or has too few associations) is "lost":
  // its pose stays the previous one and it is not integrated.
  double max_step_translation = 0.2, max_step_rotation_degrees = 20;
  // Colour features (features.hpp; needs colour frames and a build with OpenCV). Each
  // frame's ORB features are registered against the last tracked frame's (and, when few
  // agree, the nearest keyframes'). ICP from the previous pose runs first; when a feature
  // pose with at least 2 x feature.min_inliers inliers lies further than
  // feature_icp_translation / _rotation_degrees from ICP's answer, ICP also runs from the
  // feature pose (against the model raycast there) and the answer with more associated
  // pixels is kept. When ICP from the previous pose fails, it starts from the feature
  // pose. A frame that still fails is relocalised against all keyframes (a tracked frame
  // becomes one when it is keyframe_translation or keyframe_rotation_degrees from the
  // last), then refined by ICP. ICP's answer from a feature pose is kept when it stays
  // within feature_icp_translation / _rotation_degrees of it; otherwise (or when ICP
  // fails) the feature pose is kept if at least 2 x feature.min_inliers agreed, and the
  // frame is lost if not.
  bool features = true;
  FeatureParams feature;
  // Photometric term (with colour frames): next to point-to-plane ICP, each model pixel
  // of the previous frame's view (its raycast vertex, its intensity in [0, 1] in the
  // previous colour frame) is projected into the current frame, and the intensity
  // difference there (Huber-weighted beyond photometric_huber) joins the same normal
  // equations, weighted by photometric_weight against the geometric residuals in metres:
  // texture holds the motions that planar geometry leaves free (sliding along a wall).
  // Coarse to fine on the same pyramid as ICP. 0 disables it.
  double photometric_weight = 0.01;
  double photometric_huber = 0.1;
  double keyframe_translation = 0.1, keyframe_rotation_degrees = 8.0;
  double feature_icp_translation = 0.1, feature_icp_rotation_degrees = 6.0;
  // ICP's answer is refused when fewer than this fraction of the frame's valid pixels
  // found a model point (a jump ICP cannot follow converges to a wrong place with a
  // small overlap). A lost frame is kept (up to max_pending of them) and registered
  // again against each later tracked frame; when that succeeds it is placed and fused.
  double min_overlap = 0.25;
  std::size_t max_pending = 4;
  // Relocalisation (a lost frame against keyframes, or later against a tracked frame)
  // also accepts registrations with this many inliers (fewer than feature.min_inliers)
  // when ICP from there converges within feature_icp_* of it with min_overlap of the
  // frame associated: the geometry confirms what the few features say.
  int relocalisation_min_inliers = 6;
  // When ORB cannot relocalise a frame, SIFT features (feature.sift_*) of it are
  // registered against those of the wide_keyframes keyframes nearest to the last pose,
  // under the same rules. SIFT is extracted only then (for a keyframe, once: its colour
  // and depth frames are kept for it), so tracking that holds never pays for it.
  // The frames kept for SIFT cost ~2 MiB a keyframe at 640 x 480, so only the
  // wide_frames_kept newest keyframes keep theirs (older ones keep their SIFT features
  // if they were extracted, else none): memory stays bounded on long sequences.
  bool wide_features = true;
  std::size_t wide_keyframes = 4;
  std::size_t wide_frames_kept = 32;
  // Loop closure (loop_closure.hpp): when a tracked frame becomes a keyframe, its features
  // are registered against the (up to 3) nearest keyframes older than the last
  // loop_skip_keyframes; a registration with loop_min_inliers inliers whose pose lies
  // within loop_gate_translation / _rotation_degrees of the tracked one (drift, not a
  // different place that looks alike) is a loop edge.
  // The trajectory is corrected (and the map integrated again) only when a loop edge
  // disagrees with it by more than loop_min_correction metres or _degrees: below that,
  // frame-to-model tracking has closed the loop already, better than features measure it.
  bool loop_closure = true;
  std::size_t loop_skip_keyframes = 5;
  int loop_min_inliers = 40;
  double loop_gate_translation = 0.5, loop_gate_rotation_degrees = 30.0;
  double loop_min_correction = 0.03, loop_min_correction_degrees = 2.0;
  // Keyframe refinement (keyframe_refinement.hpp): at the end of a sequence (after loop
  // closure), the keyframes' depth is aligned jointly, every keyframe with its overlapping
  // ones, at refine_level of the pyramid (1 = half size: ~1.8 MiB a keyframe at 640 x 480
  // while it runs). When a keyframe moves by more than refine_min_move metres or
  // _degrees, every frame moves with its keyframe and the map is integrated again;
  // below that the tracked trajectory is kept as it is: integrating again costs about a
  // quarter of the tracking time, for millimetres where tracking already holds (the
  // generated 300-frame room: 0.33 to 0.20 cm, keyframes moved by up to 1 cm / 0.55
  // degrees). Real frames far apart move by centimetres (the Kinect frames: 12 cm).
  // The views are halved further while all of them together would exceed refine_memory
  // bytes; when even the smallest level would, the refinement is skipped (and said so).
  bool refine_keyframes = true;
  int refine_level = 1;
  std::size_t refine_memory = std::size_t{512} << 20;
  double refine_min_move = 0.02, refine_min_move_degrees = 1.0;
  unsigned threads = 0;  // 0 = vola::thread_count() (the hardware's count unless set)
  // Throws InvalidArgument for values that make no sense.
  void check() const;
};

// Intensity in [0, 1] per pixel, row-major (the photometric term's images).
struct IntensityImage {
  std::uint32_t width = 0, height = 0;
  std::vector<float> values;
};
using IntensityPyramid = std::array<IntensityImage, kPyramidLevels>;
// Grey levels of an RGB image (Rec. 601 weights) and its 2x2-averaged halvings.
IntensityPyramid intensity_pyramid(const RgbImage& rgb);

// The model surface seen from a pose: world-coordinate vertices and normals per pixel.
struct ModelView {
  std::array<VertexMap, kPyramidLevels> levels;
};

struct FrameResult {
  Pose pose = Pose::Identity();
  bool tracked = true;     // false: tracking and relocalisation failed, the previous pose was kept
  bool relocalised = false;  // the previous frame was lost; this one was placed by registering against keyframes
  bool wide_baseline = false;  // ICP started from the feature pose (large motion)
  int correspondences = 0;  // at level 0 in the last iteration
  int feature_inliers = 0;  // of the feature registration used (0: none)
};

template <class Store>
class Fusion {
 public:
  // The volume's geometry comes with the store; its voxel size must match params'.
  Fusion(Store& store, const Intrinsics& intrinsics, std::uint32_t width, std::uint32_t height,
         const FusionParams& params);
  // A lost frame placed later (see min_overlap): its index among the processed frames
  // (0 = the first) and pose. take_recovered() hands them over once.
  struct Recovered {
    std::size_t frame = 0;
    Pose pose;
    int feature_inliers = 0;
  };
  std::vector<Recovered> take_recovered() { return std::exchange(recovered_, {}); }
  // Tracks (from the second frame on) and integrates one frame. `rgb` may be null or
  // must have the depth's size. The first frame is placed at `initial_pose`.
  FrameResult process(const DepthImage& depth, const RgbImage* rgb, const Pose& initial_pose = Pose::Identity());
  // Integrates one frame at a known pose (mapping only, no tracking).
  FrameResult process_at_pose(const DepthImage& depth, const RgbImage* rgb, const Pose& pose);
  // Integrates one frame at a pose, without tracking or a new model raycast (mapping
  // again after a loop correction).
  void integrate_at_pose(const DepthImage& depth, const RgbImage* rgb, const Pose& pose);
  // The loop edges found so far, and the keyframes they join (poses as tracked).
  const std::vector<LoopEdge>& loops() const noexcept { return loops_; }
  std::vector<KeyframePose> keyframe_poses() const;
  const Pose& pose() const noexcept { return pose_; }
  std::size_t frames() const noexcept { return frames_; }
  Store& store() noexcept { return store_; }

 private:
  // ICP from `start` against `model` (raycast from model_pose).
  // With `intensity` (the current frame's), the photometric term against the previous
  // frame's view (model_ and reference_intensity_) joins the geometric one.
  std::optional<Pose> track(const std::array<VertexMap, kPyramidLevels>& frame, const Pose& start,
                            const ModelView& model, const Pose& model_pose, const std::optional<Pose>& prediction,
                            int* correspondences, const IntensityPyramid* intensity = nullptr) const;
  // ICP from a feature pose against the model raycast from it, checked against it.
  std::optional<Pose> refine_feature_pose(const std::array<VertexMap, kPyramidLevels>& frame, const Pose& guess,
                                          int inliers, int* correspondences) const;
  ModelView model_at(const Pose& pose) const;
  // SIFT features of a frame, extracted on first use from the frames kept for them.
  struct WideFeatures {
    RgbImage rgb;
    DepthImage depth;  // as ORB's (near-clipped only)
    std::optional<FeatureFrame> sift;
  };
  const FeatureFrame& sift_of(WideFeatures& wide) const;
  // The wide_keyframes nearest keyframes' SIFT features against the frame's: ICP
  // refines the best registration, as for ORB relocalisation.
  std::optional<Pose> relocalise_wide(WideFeatures& wide, const std::array<VertexMap, kPyramidLevels>& maps,
                                      FrameResult& result, int* correspondences);
  void remember_features(FeatureFrame&& features, std::optional<WideFeatures>&& wide);
  void release_old_wide_frames();
  // Indices of up to `count` keyframes, nearest to pose_ first.
  std::vector<std::size_t> nearest_keyframes(std::size_t count) const;
  static constexpr std::size_t kNearbyKeyframes = 4;
  FeatureParams weak_feature_params() const;
  DepthImage clipped(const DepthImage& raw, const RgbImage* rgb) const;
  DepthImage filtered(const DepthImage& depth) const;
  std::array<VertexMap, kPyramidLevels> frame_maps(const DepthImage& depth) const;
  void integrate_and_predict(const DepthImage& depth, const RgbImage* rgb);
  void integrate(const DepthImage& depth, const RgbImage* rgb, const Pose& pose);

  Store& store_;
  Intrinsics intrinsics_;
  std::uint32_t width_, height_;
  FusionParams params_;
  Pose pose_ = Pose::Identity();
  std::optional<Pose> motion_;  // the last tracked frame-to-frame motion, previous^-1 * current
  std::size_t frames_ = 0;
  ModelView model_;
  struct Keyframe {
    FeatureFrame features;
    Pose pose;
    std::size_t frame = 0;  // index among the processed frames
    std::optional<WideFeatures> wide;
  };
  FeatureFrame last_features_;  // of the last tracked frame, at pose_
  std::optional<IntensityPyramid> reference_intensity_;  // the last tracked frame's, seen as model_
  struct Pending {
    std::size_t frame = 0;
    FeatureFrame features;
    std::array<VertexMap, kPyramidLevels> maps;
    DepthImage depth;
    std::optional<RgbImage> rgb;
  };
  std::vector<Pending> pending_;  // lost frames, oldest first
  std::vector<Recovered> recovered_;
  bool previous_lost_ = false;
  void retry_pending();
  std::vector<Keyframe> keyframes_;
  void detect_loop(const FeatureFrame& features);
  std::vector<LoopEdge> loops_;
};

// Raycasts the TSDF from `pose` through the pinhole camera: world vertices and normals
// of the zero crossing per pixel (NaN where the ray finds none).
template <class Store>
VertexMap raycast(const Store& store, const Intrinsics& k, std::uint32_t width, std::uint32_t height,
                  const Pose& pose, const FusionParams& params);

// A shaded picture of the map from `pose`: the stored colour (grey when none was
// integrated) lit by the surface normal, black where nothing is seen.
template <class Store>
RgbImage render_view(const Store& store, const Intrinsics& k, std::uint32_t width, std::uint32_t height,
                     const Pose& pose, const FusionParams& params, bool use_colour);

// The bricks whose voxels lie within `truncation` of a measured depth along its pixel
// ray, in the order both stores allocate them (sorted); the same list on any number of
// threads (0: vola::thread_count()).
std::vector<BrickCoord> bricks_in_band(const DepthImage& depth, const Intrinsics& k, const Pose& pose,
                                       const VolumeGeometry& geometry, double truncation, unsigned threads = 0);

}  // namespace vola::slam
