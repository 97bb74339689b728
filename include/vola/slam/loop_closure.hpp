// Loop closure for vola fuse: a tracked keyframe whose colour features register against
// an older keyframe (not one of the last few, which tracking already ties it to) gives a
// loop edge; at the end of a sequence a pose graph over the keyframes (odometry edges
// between consecutive keyframes as tracked, the loop edges as registered) spreads the
// loop's disagreement along the chain, every frame moves with the keyframe it was
// tracked after, and the map is integrated again at the corrected poses.
#pragma once

#include <cstddef>
#include <vector>

#include "vola/slam/pose_graph.hpp"
#include "vola/slam/sequence.hpp"

namespace vola::slam {

struct KeyframePose {
  std::size_t frame = 0;  // index among the processed frames
  Pose pose = Pose::Identity();
};

struct LoopEdge {
  std::size_t older = 0, newer = 0;               // keyframe indices
  Pose measured = Pose::Identity();               // older^-1 * newer, from the features
  int inliers = 0;
};

struct LoopCorrection {
  std::vector<Pose> poses;          // every frame's corrected pose
  double max_keyframe_move = 0.0;   // metres, the largest change of a keyframe's position
  PoseGraphResult graph;
};

// How far the loop edges disagree with the keyframes as tracked: the largest
// translation (metres) and rotation (degrees) of measured^-1 * older^-1 * newer.
struct LoopDisagreement {
  double metres = 0.0, degrees = 0.0;
};
LoopDisagreement loop_disagreement(const std::vector<KeyframePose>& keyframes, const std::vector<LoopEdge>& loops);

// Odometry edges are weighted as 1 cm / 0.5 degree, loop edges as 2 cm / 1 degree
// (features are less precise than ICP). Frame f moves with the last keyframe at or
// before it (the first keyframe for frames before it). Throws InvalidArgument for a
// keyframe or loop naming a frame or keyframe that does not exist.
// Every frame moved with its keyframe: frame f, tracked after keyframe a (the last one
// at or before it in frame order; the first keyframe for frames before it), becomes
// moved[a] * keyframes[a].pose^-1 * frame_poses[f]. Throws InvalidArgument when moved
// and keyframes differ in number or a keyframe names a frame that does not exist.
std::vector<Pose> move_with_keyframes(const std::vector<Pose>& frame_poses, const std::vector<KeyframePose>& keyframes,
                                      const std::vector<Pose>& moved);

LoopCorrection correct_trajectory(const std::vector<Pose>& frame_poses, const std::vector<KeyframePose>& keyframes,
                                  const std::vector<LoopEdge>& loops);

}  // namespace vola::slam
