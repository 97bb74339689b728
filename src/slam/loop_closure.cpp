#include "vola/slam/loop_closure.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "vola/error.hpp"

namespace vola::slam {

namespace {

PoseGraphEdge edge(std::size_t from, std::size_t to, const Pose& measured, double metres, double degrees) {
  const double radians = degrees * M_PI / 180.0;
  return {from, to, measured, 1.0 / (metres * metres), 1.0 / (radians * radians)};
}

// The keyframes' indices in frame order (a lost frame placed later becomes a keyframe late).
std::vector<std::size_t> frame_order(const std::vector<KeyframePose>& keyframes) {
  std::vector<std::size_t> chain(keyframes.size());
  for (std::size_t k = 0; k < chain.size(); ++k) chain[k] = k;
  std::stable_sort(chain.begin(), chain.end(),
                   [&](std::size_t a, std::size_t b) { return keyframes[a].frame < keyframes[b].frame; });
  return chain;
}

}  // namespace

LoopDisagreement loop_disagreement(const std::vector<KeyframePose>& keyframes, const std::vector<LoopEdge>& loops) {
  LoopDisagreement worst;
  for (const LoopEdge& loop : loops) {
    if (loop.older >= keyframes.size() || loop.newer >= keyframes.size())
      throw InvalidArgument("loop closure: a loop names keyframe " + std::to_string(std::max(loop.older, loop.newer)) +
                            " of " + std::to_string(keyframes.size()));
    const Pose d = loop.measured.inverse() * keyframes[loop.older].pose.inverse() * keyframes[loop.newer].pose;
    worst.metres = std::max(worst.metres, d.translation().norm());
    worst.degrees = std::max(worst.degrees, Eigen::AngleAxisd(d.linear()).angle() * 180.0 / M_PI);
  }
  return worst;
}

LoopCorrection correct_trajectory(const std::vector<Pose>& frame_poses, const std::vector<KeyframePose>& keyframes,
                                  const std::vector<LoopEdge>& loops) {
  for (std::size_t k = 0; k < keyframes.size(); ++k)
    if (keyframes[k].frame >= frame_poses.size())
      throw InvalidArgument("loop closure: keyframe " + std::to_string(k) + " names frame " +
                            std::to_string(keyframes[k].frame) + " of " + std::to_string(frame_poses.size()));
  for (const LoopEdge& loop : loops)
    if (loop.older >= keyframes.size() || loop.newer >= keyframes.size())
      throw InvalidArgument("loop closure: a loop names keyframe " + std::to_string(std::max(loop.older, loop.newer)) +
                            " of " + std::to_string(keyframes.size()));
  LoopCorrection out;
  out.poses = frame_poses;
  if (keyframes.size() < 2 || loops.empty()) return out;
  const std::vector<std::size_t> chain = frame_order(keyframes);
  // Graph node j is chain[j]; the graph holds node 0, the first keyframe, fixed.
  std::vector<Pose> ordered(chain.size());
  std::vector<std::size_t> place(chain.size());
  for (std::size_t j = 0; j < chain.size(); ++j) {
    ordered[j] = keyframes[chain[j]].pose;
    place[chain[j]] = j;
  }
  std::vector<PoseGraphEdge> edges;
  for (std::size_t j = 1; j < chain.size(); ++j)
    edges.push_back(edge(j - 1, j, Pose(ordered[j - 1].inverse() * ordered[j]), 0.01, 0.5));
  for (const LoopEdge& loop : loops) edges.push_back(edge(place[loop.older], place[loop.newer], loop.measured, 0.02, 1.0));
  out.graph = optimise_pose_graph(ordered, edges);
  std::vector<Pose> moved(keyframes.size());
  for (std::size_t j = 0; j < chain.size(); ++j) {
    moved[chain[j]] = ordered[j];
    out.max_keyframe_move =
        std::max(out.max_keyframe_move, (ordered[j].translation() - keyframes[chain[j]].pose.translation()).norm());
  }
  out.poses = move_with_keyframes(frame_poses, keyframes, moved);
  return out;
}

std::vector<Pose> move_with_keyframes(const std::vector<Pose>& frame_poses, const std::vector<KeyframePose>& keyframes,
                                      const std::vector<Pose>& moved) {
  if (moved.size() != keyframes.size())
    throw InvalidArgument("moving frames with their keyframes: " + std::to_string(moved.size()) + " poses for " +
                          std::to_string(keyframes.size()) + " keyframes");
  for (std::size_t k = 0; k < keyframes.size(); ++k)
    if (keyframes[k].frame >= frame_poses.size())
      throw InvalidArgument("moving frames with their keyframes: keyframe " + std::to_string(k) + " names frame " +
                            std::to_string(keyframes[k].frame) + " of " + std::to_string(frame_poses.size()));
  if (keyframes.empty()) return frame_poses;
  const std::vector<std::size_t> chain = frame_order(keyframes);
  std::vector<Pose> out(frame_poses.size());
  std::size_t anchor = 0;  // position in the chain
  for (std::size_t f = 0; f < frame_poses.size(); ++f) {
    while (anchor + 1 < chain.size() && keyframes[chain[anchor + 1]].frame <= f) ++anchor;
    const std::size_t k = chain[anchor];
    out[f] = moved[k] * keyframes[k].pose.inverse() * frame_poses[f];
  }
  return out;
}

}  // namespace vola::slam
