#include "vola/slam/sequence_generator.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <optional>

#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/output_stream.hpp"
#include "vola/raycast/world.hpp"

namespace vola::slam {

namespace fs = std::filesystem;

namespace {

struct Colour {
  double r, g, b;
};

// Collects voxel centres with colours; duplicates are averaged by the builder.
class SceneBuilder {
 public:
  explicit SceneBuilder(double voxel_size) : vs_(voxel_size) {}
  // Every voxel whose centre lies in [lo, hi] and, when shell, within a voxel of its boundary.
  template <class ColourAt>
  void box(Eigen::Vector3d lo, Eigen::Vector3d hi, bool shell, ColourAt colour_at) {
    const Eigen::Vector3i a = index(lo), b = index(hi);
    for (int z = a.z(); z <= b.z(); ++z)
      for (int y = a.y(); y <= b.y(); ++y)
        for (int x = a.x(); x <= b.x(); ++x) {
          const bool boundary = x == a.x() || x == b.x() || y == a.y() || y == b.y() || z == a.z() || z == b.z();
          if (shell && !boundary) continue;
          add(x, y, z, colour_at(centre(x, y, z)));
        }
  }
  // Voxels within a voxel inside the surface of a ball or a vertical cylinder.
  void ball(const Eigen::Vector3d& c, double radius, Colour colour) {
    const Eigen::Vector3i a = index(c - Eigen::Vector3d::Constant(radius)), b = index(c + Eigen::Vector3d::Constant(radius));
    for (int z = a.z(); z <= b.z(); ++z)
      for (int y = a.y(); y <= b.y(); ++y)
        for (int x = a.x(); x <= b.x(); ++x) {
          const double d = (centre(x, y, z) - c).norm();
          if (d <= radius && d > radius - 1.5 * vs_) add(x, y, z, colour);
        }
  }
  void cylinder(double cx, double cy, double radius, double z0, double z1, Colour colour) {
    const Eigen::Vector3i a = index({cx - radius, cy - radius, z0}), b = index({cx + radius, cy + radius, z1});
    for (int z = a.z(); z <= b.z(); ++z)
      for (int y = a.y(); y <= b.y(); ++y)
        for (int x = a.x(); x <= b.x(); ++x) {
          const Eigen::Vector3d p = centre(x, y, z);
          const double d = std::hypot(p.x() - cx, p.y() - cy);
          if (d <= radius && d > radius - 1.5 * vs_) add(x, y, z, colour);
        }
  }
  Tree build_tree() {
    BuildOptions options;
    options.quantization = Quantization::grid;
    options.voxel_size = vs_;
    options.origin = Point{kOrigin, kOrigin, kOrigin};
    options.depth = depth_for_extent(5.2 - kOrigin, vs_);
    cloud_.attributes = {red_, green_, blue_};
    return build(cloud_, options);
  }

 private:
  static constexpr double kOrigin = -0.1;  // the grid starts a little outside the room
  Eigen::Vector3i index(const Eigen::Vector3d& p) const {
    return ((p - Eigen::Vector3d::Constant(kOrigin)) / vs_).array().floor().cast<int>();
  }
  Eigen::Vector3d centre(int x, int y, int z) const {
    return Eigen::Vector3d::Constant(kOrigin) + vs_ * Eigen::Vector3d(x + 0.5, y + 0.5, z + 0.5);
  }
  void add(int x, int y, int z, Colour c) {
    const Eigen::Vector3d p = centre(x, y, z);
    cloud_.xyz.insert(cloud_.xyz.end(), {p.x(), p.y(), p.z()});
    red_.values.push_back(c.r);
    green_.values.push_back(c.g);
    blue_.values.push_back(c.b);
  }
  double vs_;
  PointCloud cloud_;
  PointAttribute red_{"red", ValueType::u8, Reduction::mean, {}}, green_{"green", ValueType::u8, Reduction::mean, {}},
      blue_{"blue", ValueType::u8, Reduction::mean, {}};
};

auto plain(Colour c) {
  return [c](const Eigen::Vector3d&) { return c; };
}

}  // namespace

Tree room_scene(double voxel_size) {
  if (!(voxel_size > 0.0) || voxel_size > 0.1) throw InvalidArgument("room scene: voxel size must be in (0, 0.1] m");
  SceneBuilder s(voxel_size);
  using V = Eigen::Vector3d;
  const double t = 0.02;  // wall thickness
  // Floor: 0.5 m checkerboard tiles.
  s.box(V(-t, -t, -t), V(4 + t, 5 + t, 0), false, [](const V& p) {
    const bool dark = (static_cast<int>(std::floor(p.x() / 0.5)) + static_cast<int>(std::floor(p.y() / 0.5))) % 2;
    return dark ? Colour{120, 80, 50} : Colour{200, 160, 110};
  });
  s.box(V(-t, -t, 2.6), V(4 + t, 5 + t, 2.6 + t), false, plain({235, 235, 230}));
  // Walls with a darker band at skirting height.
  auto wall = [](Colour c) {
    return [c](const V& p) { return p.z() < 0.12 ? Colour{c.r * 0.5, c.g * 0.5, c.b * 0.5} : c; };
  };
  s.box(V(-t, -t, 0), V(0, 5 + t, 2.6), false, wall({170, 190, 210}));
  s.box(V(4, -t, 0), V(4 + t, 5 + t, 2.6), false, wall({210, 200, 160}));
  s.box(V(-t, -t, 0), V(4 + t, 0, 2.6), false, wall({190, 210, 180}));
  s.box(V(-t, 5, 0), V(4 + t, 5 + t, 2.6), false, wall({215, 185, 185}));
  // Furniture.
  s.box(V(2.6, 3.6, 0.72), V(3.8, 4.4, 0.76), true, plain({140, 90, 40}));  // table top and legs
  for (const auto& leg : {V(2.65, 3.65, 0), V(3.7, 3.65, 0), V(2.65, 4.3, 0), V(3.7, 4.3, 0)})
    s.box(leg, leg + V(0.05, 0.05, 0.72), true, plain({90, 60, 30}));
  s.box(V(0, 1.0, 0), V(0.5, 2.0, 1.8), true, plain({245, 245, 245}));       // cabinet
  s.box(V(3.4, 0.5, 0), V(3.9, 1.0, 0.5), true, plain({180, 140, 90}));      // boxes
  s.box(V(3.5, 0.6, 0.5), V(3.8, 0.9, 0.8), true, plain({200, 60, 50}));
  s.ball(V(3.2, 4.0, 0.96), 0.2, {40, 120, 200});                             // a ball on the table
  s.cylinder(1.0, 4.2, 0.15, 0, 2.6, {230, 230, 220});                        // column
  s.box(V(0.8, 4.3, 0), V(2.4, 5.0, 0.45), true, plain({60, 110, 70}));      // sofa seat and back
  s.box(V(0.8, 4.8, 0.45), V(2.4, 5.0, 0.9), true, plain({50, 100, 60}));
  // Pictures, a shelf and a radiator on every wall (a bare wall leaves ICP a free axis).
  s.box(V(1.0, 0, 1.2), V(1.8, 0.04, 1.8), true, plain({200, 180, 40}));
  s.box(V(2.5, 0, 1.0), V(3.0, 0.03, 1.6), true, plain({60, 60, 160}));
  s.box(V(3.96, 2.0, 1.3), V(4.0, 3.0, 1.9), true, plain({160, 40, 120}));
  s.box(V(3.75, 3.2, 1.0), V(4.0, 4.2, 1.05), true, plain({120, 120, 120}));
  s.box(V(3.9, 1.5, 0.2), V(4.0, 2.5, 0.8), true, plain({250, 250, 250}));
  s.box(V(0, 3.0, 1.2), V(0.03, 3.8, 1.7), true, plain({30, 150, 150}));
  s.box(V(2.8, 4.97, 1.3), V(3.6, 5.0, 1.8), true, plain({220, 120, 40}));
  return s.build_tree();
}

std::vector<Pose> room_trajectory(std::size_t frames, double degrees_per_frame) {
  std::vector<Pose> poses;
  const Eigen::Vector3d up(0, 0, 1);
  for (std::size_t i = 0; i < frames; ++i) {
    const double theta = static_cast<double>(i) * degrees_per_frame * M_PI / 180.0;
    const Eigen::Vector3d position(2.0 + 0.6 * std::cos(theta), 2.5 + 0.8 * std::sin(theta), 1.4 + 0.1 * std::sin(3 * theta));
    const double yaw = theta + 0.3 * std::sin(2 * theta), pitch = -0.3 + 0.1 * std::sin(5 * theta);
    const Eigen::Vector3d forward(std::cos(yaw) * std::cos(pitch), std::sin(yaw) * std::cos(pitch), std::sin(pitch));
    const Eigen::Vector3d right = forward.cross(up).normalized();
    const Eigen::Vector3d down = forward.cross(right);
    Eigen::Matrix3d r;
    r << right, down, forward;  // camera axes (x right, y down, z forward) in world coordinates
    const double roll = 0.05 * std::sin(4 * theta);
    Pose pose = Pose::Identity();
    pose.linear() = r * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    pose.translation() = position;
    poses.push_back(pose);
  }
  return poses;
}

RenderedFrame render_frame(const raycast::RayCaster& caster, const Pose& pose, const GeneratorOptions& options,
                           std::mt19937_64& rng) {
  const Tree& scene = caster.tree();
  const Frame frame = scene.frame();
  const Intrinsics& k = options.intrinsics;
  const std::size_t n = std::size_t{options.width} * options.height;
  std::vector<raycast::Ray> rays(n);
  std::vector<double> scale(n);  // ray length per metre of depth
  for (std::uint32_t v = 0; v < options.height; ++v)
    for (std::uint32_t u = 0; u < options.width; ++u) {
      const Eigen::Vector3d camera((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
      const std::size_t i = std::size_t{v} * options.width + u;
      scale[i] = camera.norm();
      const Eigen::Vector3d d = pose.linear() * (camera / scale[i]);
      const Eigen::Vector3d o = pose.translation();
      raycast::Ray world{{o.x(), o.y(), o.z()}, {d.x(), d.y(), d.z()}, options.noise.max_range * scale[i] * 1.5};
      rays[i] = raycast::world_ray_to_grid(frame, world);
    }
  std::vector<std::optional<raycast::RayHit>> hits(n);
  caster.cast(rays, hits, options.threads);
  const AttributeColumn* red = scene.attributes().find("red");
  const AttributeColumn* green = scene.attributes().find("green");
  const AttributeColumn* blue = scene.attributes().find("blue");
  RenderedFrame out;
  out.depth = {options.width, options.height, std::vector<float>(n, 0.0f)};
  out.rgb = {options.width, options.height, std::vector<std::uint8_t>(n * 3, 0)};
  std::normal_distribution<double> gaussian;
  std::uniform_real_distribution<double> uniform;
  const DepthNoise& noise = options.noise;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& hit = hits[i];
    // Draw the random numbers for every pixel, so a pixel's noise does not depend on
    // whether others hit.
    const double g = gaussian(rng), drop = uniform(rng);
    if (!hit) continue;
    const double z = hit->t * frame.voxel_size / scale[i];
    const Eigen::Vector3d normal(hit->normal[0], hit->normal[1], hit->normal[2]);
    const Eigen::Vector3d dir(rays[i].direction[0], rays[i].direction[1], rays[i].direction[2]);
    const double cosine = std::clamp(-normal.dot(dir), 0.0, 1.0);
    const double angle = std::acos(cosine);
    double shade = 0.3 + 0.7 * cosine;
    double rgb[3] = {180, 180, 180};
    if (const auto rank = scene.rank(hit->voxel); rank && red && green && blue) {
      rgb[0] = red->get(*rank);
      rgb[1] = green->get(*rank);
      rgb[2] = blue->get(*rank);
    }
    for (int c = 0; c < 3; ++c) out.rgb.rgb[i * 3 + c] = static_cast<std::uint8_t>(std::lround(std::min(255.0, rgb[c] * shade)));
    if (!noise.enabled) {
      out.depth.metres[i] = static_cast<float>(z);
      continue;
    }
    if (z < noise.min_range || z > noise.max_range) continue;
    if (angle > noise.dropout_angle_degrees * M_PI / 180.0 || drop < noise.dropout_probability) continue;
    const double half_pi = M_PI / 2;
    double sigma = noise.axial_base + noise.axial_quadratic * (z - 0.4) * (z - 0.4);
    if (angle > 0.0) sigma += 0.0001 / std::sqrt(z) * angle * angle / ((half_pi - angle) * (half_pi - angle));
    out.depth.metres[i] = static_cast<float>(std::max(0.0, z + sigma * g));
  }
  return out;
}

void generate_sequence(const Tree& scene, const std::vector<Pose>& poses, const GeneratorOptions& options,
                       const std::string& directory, const std::function<void(std::size_t, std::size_t)>& progress) {
  options.intrinsics.check();
  if (options.width == 0 || options.height == 0) throw InvalidArgument("image size must be positive");
  if (!(options.depth_factor > 0.0) || !(options.frame_rate > 0.0))
    throw InvalidArgument("depth factor and frame rate must be positive");
  const fs::path dir(directory);
  fs::create_directories(dir / "depth");
  if (options.colour) fs::create_directories(dir / "rgb");
  OutputStream depth_list((dir / "depth.txt").string()), truth((dir / "groundtruth.txt").string());
  std::optional<OutputStream> rgb_file;
  if (options.colour) rgb_file.emplace((dir / "rgb.txt").string());
  std::ostream& rgb_list = rgb_file ? static_cast<std::ostream&>(*rgb_file) : depth_list;  // used only with colour
  depth_list << "# depth maps: timestamp filename (vola rgbd-generate)\n" << std::fixed << std::setprecision(6);
  truth << "# ground truth trajectory: timestamp tx ty tz qx qy qz qw\n" << std::setprecision(17);
  if (options.colour) rgb_list << "# colour images: timestamp filename\n" << std::fixed << std::setprecision(6);
  write_intrinsics((dir / "intrinsics.txt").string(), options.intrinsics);
  const raycast::RayCaster caster(scene);
  std::mt19937_64 rng(options.seed);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const RenderedFrame frame = render_frame(caster, poses[i], options, rng);
    char name[32];
    std::snprintf(name, sizeof name, "%06zu.png", i);
    const double timestamp = 1.0 + static_cast<double>(i) / options.frame_rate;
    write_depth_png((dir / "depth" / name).string(), frame.depth, options.depth_factor);
    depth_list << timestamp << " depth/" << name << '\n';
    if (options.colour) {
      write_rgb_png((dir / "rgb" / name).string(), frame.rgb);
      rgb_list << timestamp << " rgb/" << name << '\n';
    }
    const Eigen::Quaterniond q(poses[i].linear());
    const Eigen::Vector3d p = poses[i].translation();
    truth << std::fixed << std::setprecision(6) << timestamp << std::defaultfloat << std::setprecision(17) << ' ' << p.x()
          << ' ' << p.y() << ' ' << p.z() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << q.w() << '\n';
    if (progress) progress(i + 1, poses.size());
  }
  depth_list.commit();
  truth.commit();
  if (rgb_file) rgb_file->commit();
}

}  // namespace vola::slam
