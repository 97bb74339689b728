#include "vola/raycast/avoidance.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "vola/error.hpp"

namespace vola::raycast {
namespace {

Point add(const Point& a, const Point& b, double s = 1.0) { return {a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]}; }
Point sub(const Point& a, const Point& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const Point& a, const Point& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const Point& a) { return std::sqrt(dot(a, a)); }
Point scaled(const Point& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
Point cross(const Point& a, const Point& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
bool finite(const Point& p) { return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]); }

// Two unit vectors perpendicular to the unit vector d and to each other.
void perpendiculars(const Point& d, Point& u, Point& v) {
  const Point helper = std::fabs(d[0]) < 0.9 ? Point{1, 0, 0} : Point{0, 1, 0};
  u = cross(d, helper);
  u = scaled(u, 1.0 / norm(u));
  v = cross(d, u);
}

// Spacing of the sphere queries that check a step.
constexpr double kSweepSpacing = 0.25;

}  // namespace

ObstacleAvoider::ObstacleAvoider(const Collider& collider, const AvoidanceOptions& options)
    : collider_(&collider), options_(options) {
  if (!(options.radius >= 0.0) || !std::isfinite(options.radius))
    throw InvalidArgument("avoidance: the radius must be finite and >= 0");
  if (!(options.speed > 0.0) || !std::isfinite(options.speed)) throw InvalidArgument("avoidance: the speed must be > 0");
  if (!(options.look_ahead > 0.0) || !std::isfinite(options.look_ahead))
    throw InvalidArgument("avoidance: the look-ahead must be > 0");
  if (options.rings < 2 || options.rays_per_ring < 3)
    throw InvalidArgument("avoidance: the fan needs at least 2 rings of 3 rays");
}

double ObstacleAvoider::clearance(const Point& position, const Point& d, double limit) const {
  Point u, v;
  perpendiculars(d, u, v);
  const double r = options_.radius;
  const Point offsets[5] = {{0, 0, 0}, scaled(u, r), scaled(u, -r), scaled(v, r), scaled(v, -r)};
  double free = limit;
  for (const Point& offset : offsets) {
    if (r == 0.0 && offset != Point{0, 0, 0}) continue;
    const Ray ray{add(position, offset), d, free};
    if (const auto hit = collider_->caster().cast(ray)) free = std::min(free, hit->t);
  }
  return free;
}

bool ObstacleAvoider::sweep_is_free(const Point& a, const Point& b) const {
  const double length = norm(sub(b, a));
  const auto samples = static_cast<int>(std::ceil(length / kSweepSpacing));
  // Every point of the segment is within half a spacing of a sample, so a sphere that
  // much larger at each sample covers the swept sphere.
  const double grown = options_.radius + 0.5 * (samples ? length / samples : 0.0);
  for (int i = 0; i <= samples; ++i) {
    const double s = samples ? static_cast<double>(i) / samples : 0.0;
    if (collider_->sphere(add(a, sub(b, a), s), grown)) return false;
  }
  return true;
}

AvoidanceStep ObstacleAvoider::step(const Point& position, const Point& velocity, const Point& goal) const {
  if (!finite(position) || !finite(velocity) || !finite(goal))
    throw InvalidArgument("avoidance: position, velocity and goal must be finite");
  if (collider_->sphere(position, options_.radius))
    throw InvalidArgument("avoidance: the agent at the position touches an occupied voxel");
  AvoidanceStep result;
  result.position = position;
  const Point to_goal = sub(goal, position);
  const double goal_distance = norm(to_goal);
  if (goal_distance == 0.0) return result;
  const Point g = scaled(to_goal, 1.0 / goal_distance);
  const double speed = norm(velocity);
  const Point vel = speed > 0.0 ? scaled(velocity, 1.0 / speed) : Point{0, 0, 0};
  const double reach = std::min(goal_distance, options_.look_ahead);
  const double step_length = std::min(options_.speed, goal_distance);

  struct Candidate {
    Point d;
    double clearance, score;
  };
  std::vector<Candidate> candidates;
  Point u, v;
  perpendiculars(g, u, v);
  for (int ring = 0; ring <= options_.rings; ++ring) {
    const double polar = std::numbers::pi * ring / options_.rings;
    const int around = (ring == 0 || ring == options_.rings) ? 1 : options_.rays_per_ring;
    for (int k = 0; k < around; ++k) {
      const double azimuth = 2.0 * std::numbers::pi * k / around;
      const Point side = add(scaled(u, std::cos(azimuth)), v, std::sin(azimuth));
      const Point d = add(scaled(g, std::cos(polar)), side, std::sin(polar));
      const double free = clearance(position, d, reach);
      const bool open = free >= reach;
      // Open directions rank by heading and velocity; closed ones after all open ones,
      // by clearance.
      const double score = open ? 10.0 + dot(d, g) + options_.velocity_weight * dot(d, vel) : free / reach;
      candidates.push_back({d, free, score});
    }
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  for (const Candidate& c : candidates) {
    const Point next = add(position, c.d, step_length);
    if (!sweep_is_free(position, next)) continue;
    result.heading = c.d;
    result.position = next;
    result.clearance = c.clearance;
    return result;
  }
  result.held = true;
  return result;
}

Flight fly(const ObstacleAvoider& avoider, const Point& start, const Point& goal, std::size_t max_steps,
           double tolerance) {
  Flight flight;
  flight.positions.push_back(start);
  Point position = start, velocity{0, 0, 0};
  for (std::size_t i = 0; i < max_steps; ++i) {
    if (norm(sub(goal, position)) <= tolerance) break;
    const AvoidanceStep s = avoider.step(position, velocity, goal);
    if (s.held) {
      ++flight.held_steps;
      // From rest the same question gets the same answer: there is no way on.
      if (velocity == Point{0, 0, 0}) break;
    }
    velocity = sub(s.position, position);
    position = s.position;
    flight.positions.push_back(position);
  }
  // The last leg, onto the goal itself, is checked as every step is: within the tolerance
  // is not at the goal, and the gap may hold a voxel.
  if (norm(sub(goal, position)) <= tolerance && !(position == goal) && avoider.sweep_is_free(position, goal)) {
    position = goal;
    flight.positions.push_back(position);
  }
  flight.reached = position == goal;
  return flight;
}

}  // namespace vola::raycast
