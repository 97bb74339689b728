// Reactive obstacle avoidance for a moving agent (a sphere of `radius`), in voxel-grid
// coordinates: no map search, only what a fan of rays from the agent sees each step.
//
// Each step looks along a fan of directions: rings of cones around the direction to the
// goal, from straight at it out to straight away from it. A direction's clearance is
// how far the agent's outline can go along it: the shortest of five parallel rays (the
// centre and four offset by the radius across the direction), up to `look_ahead`.
// A direction is open when that clearance reaches the goal or `look_ahead`. The agent
// takes the open direction that best combines heading for the goal and keeping its
// current velocity; with none open, the direction of most clearance. Before moving it
// checks the step itself: a sphere of the radius swept along the step must touch no
// voxel (sphere queries spaced a quarter voxel apart with the radius grown to cover the
// gaps, so the check is conservative). A step that fails the check is never taken: the
// next best direction is tried, and when none passes the agent holds its position.
// So whatever the scene, the agent never collides; it may fail to reach the goal.
#pragma once

#include <cstddef>
#include <vector>

#include "vola/raycast/collision.hpp"

namespace vola::raycast {

struct AvoidanceOptions {
  double radius = 1.0;        // agent radius in voxels
  double speed = 1.0;         // distance moved per step, in voxels
  double look_ahead = 24.0;   // length of the fan's rays, in voxels
  int rings = 12;             // cones between the goal direction and its opposite
  int rays_per_ring = 16;     // directions around each cone
  double velocity_weight = 0.5;  // preference for keeping the current direction
};

struct AvoidanceStep {
  Point heading{0, 0, 0};     // unit direction taken; zero when the agent holds
  Point position{0, 0, 0};    // where the step ends
  double clearance = 0.0;     // clearance along the heading (<= look_ahead)
  bool held = false;          // no direction passed the step check
};

class ObstacleAvoider {
 public:
  // The collider (and its tree) must outlive the avoider. Throws InvalidArgument for a
  // negative radius, a speed or look-ahead that is not positive, or fewer than 2 rings
  // or 3 rays per ring.
  ObstacleAvoider(const Collider& collider, const AvoidanceOptions& options);

  // One step from `position` (moving at `velocity`, zero when at rest) towards `goal`.
  // The step is at most `speed` long and never passes the goal. Throws InvalidArgument
  // when the agent at `position` already touches a voxel or a point is not finite.
  AvoidanceStep step(const Point& position, const Point& velocity, const Point& goal) const;

  // Clearance along the unit direction `d` from `position`, as defined above.
  double clearance(const Point& position, const Point& d, double limit) const;
  // True when a sphere of the agent's radius swept from a to b touches no voxel.
  bool sweep_is_free(const Point& a, const Point& b) const;

  const AvoidanceOptions& options() const noexcept { return options_; }

 private:
  const Collider* collider_;
  AvoidanceOptions options_;
};

struct Flight {
  std::vector<Point> positions;  // the start, then the end of every step
  bool reached = false;          // the last position is the goal
  std::size_t held_steps = 0;    // steps on which no direction was safe
};

// Steps from start towards goal until within `tolerance` of it, `max_steps` steps, or a
// step on which the agent has to hold from rest (nothing would change after it); from
// within `tolerance` a last leg onto the goal, when its sweep is free. Reached means the
// agent stands on the goal with every leg checked.
Flight fly(const ObstacleAvoider& avoider, const Point& start, const Point& goal, std::size_t max_steps,
           double tolerance = 0.5);

}  // namespace vola::raycast
