#include "vola/slam/sequence.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "vola/error.hpp"
#include "vola/output_stream.hpp"

namespace vola::slam {

namespace fs = std::filesystem;

namespace {

// Calls f(line_number, line) for every line that is not blank or a '#' comment.
template <class F>
void for_each_data_line(const std::string& file, F&& f) {
  std::ifstream in(file);
  if (!in) throw IoError(file + ": cannot open");
  std::string line;
  std::size_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (number == 1 && line.starts_with("\xef\xbb\xbf")) line.erase(0, 3);  // a UTF-8 byte order mark
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    f(number, line);
  }
}

[[noreturn]] void line_error(const std::string& file, std::size_t line, const std::string& what) {
  throw FormatError(file, std::nullopt, "line " + std::to_string(line) + ": " + what);
}

// Whitespace-separated fields of a line.
std::vector<std::string> fields_of(const std::string& line) {
  std::vector<std::string> fields;
  std::istringstream in(line);
  std::string field;
  while (in >> field) fields.push_back(field);
  return fields;
}

double parse_number(const std::string& text, const std::string& file, std::size_t line, const char* what) {
  double value = 0.0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc{} || ptr != end || !std::isfinite(value))
    line_error(file, line, std::string("expected a finite number for ") + what + ", found '" + text + "'");
  return value;
}

Pose pose_from_fields(const std::vector<std::string>& f, std::size_t first, const std::string& file,
                      std::size_t line) {
  static const char* names[] = {"tx", "ty", "tz", "qx", "qy", "qz", "qw"};
  double v[7];
  for (int i = 0; i < 7; ++i) v[i] = parse_number(f[first + i], file, line, names[i]);
  Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
  const double norm = q.norm();
  if (std::abs(norm - 1.0) > 1e-3)
    line_error(file, line, "quaternion (qx qy qz qw) has norm " + std::to_string(norm) + ", not 1");
  q.normalize();
  Pose pose = Pose::Identity();
  pose.linear() = q.toRotationMatrix();
  pose.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  return pose;
}

std::string resolve(const fs::path& directory, const std::string& path) {
  const fs::path p(path);
  return (p.is_absolute() ? p : directory / p).string();
}

// Numbered files N.ext (N >= 1) in `folder`, by N.
std::vector<std::pair<long, std::string>> numbered_files(const fs::path& folder) {
  std::vector<std::pair<long, std::string>> files;
  if (!fs::is_directory(folder)) return files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (!entry.is_regular_file()) continue;
    const std::string stem = entry.path().stem().string();
    long n = 0;
    const auto [ptr, ec] = std::from_chars(stem.data(), stem.data() + stem.size(), n);
    if (ec != std::errc{} || ptr != stem.data() + stem.size() || n < 0) continue;
    files.emplace_back(n, entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

Sequence read_numbered_layout(const fs::path& directory) {
  const auto depth = numbered_files(directory / "depth");
  if (depth.empty())
    throw FormatError(directory.string(), std::nullopt,
                      "not an RGB-D sequence: no depth.txt (TUM layout) and no numbered frames in depth/");
  auto colour = numbered_files(directory / "color");
  if (colour.empty()) colour = numbered_files(directory / "rgb");
  Sequence sequence;
  for (std::size_t i = 0; i < depth.size(); ++i) {
    if (i > 0 && depth[i].first == depth[i - 1].first)
      throw FormatError(depth[i].second, std::nullopt, "two depth frames numbered " + std::to_string(depth[i].first));
    SequenceFrame frame;
    frame.timestamp = static_cast<double>(depth[i].first);
    frame.depth_path = depth[i].second;
    const auto it = std::find_if(colour.begin(), colour.end(), [&](const auto& c) { return c.first == depth[i].first; });
    if (it != colour.end()) frame.rgb_path = it->second;
    sequence.frames.push_back(frame);
  }
  if (fs::exists(directory / "pose.txt")) sequence.groundtruth = read_numbered_poses((directory / "pose.txt").string());
  return sequence;
}

}  // namespace

Intrinsics read_intrinsics(const std::string& file) {
  std::optional<Intrinsics> k;
  for_each_data_line(file, [&](std::size_t number, const std::string& line) {
    if (k) return;
    const auto f = fields_of(line);
    if (f.size() != 4) line_error(file, number, "expected 'fx fy cx cy', found " + std::to_string(f.size()) + " fields");
    k = Intrinsics{parse_number(f[0], file, number, "fx"), parse_number(f[1], file, number, "fy"),
                   parse_number(f[2], file, number, "cx"), parse_number(f[3], file, number, "cy")};
    if (k->fx == 0.0 || k->fy == 0.0) line_error(file, number, "focal lengths must not be 0");
  });
  if (!k) throw FormatError(file, std::nullopt, "no 'fx fy cx cy' line");
  return *k;
}

void write_intrinsics(const std::string& file, const Intrinsics& k) {
  OutputStream out(file);
  out << "# fx fy cx cy (pixels)\n" << std::setprecision(17) << k.fx << ' ' << k.fy << ' ' << k.cx << ' ' << k.cy << '\n';
  out.commit();
}

std::vector<TimedPath> read_timed_list(const std::string& file) {
  std::vector<TimedPath> list;
  for_each_data_line(file, [&](std::size_t number, const std::string& line) {
    const auto fields = fields_of(line);
    if (fields.size() != 2) line_error(file, number, "expected 'timestamp path', found " + std::to_string(fields.size()) + " fields");
    list.push_back({parse_number(fields[0], file, number, "the timestamp"), fields[1], number});
  });
  return list;
}

std::vector<StampedPose> read_trajectory(const std::string& file) {
  std::vector<StampedPose> poses;
  for_each_data_line(file, [&](std::size_t number, const std::string& line) {
    const auto fields = fields_of(line);
    if (fields.size() != 8)
      line_error(file, number, "expected 'timestamp tx ty tz qx qy qz qw', found " + std::to_string(fields.size()) + " fields");
    poses.push_back({parse_number(fields[0], file, number, "the timestamp"), pose_from_fields(fields, 1, file, number)});
  });
  // In time order, as TUM's tools read them: a tracker's threads or a file put together
  // from pieces may write the lines out of order, and the relative pose error pairs poses
  // by their order.
  std::stable_sort(poses.begin(), poses.end(),
                   [](const StampedPose& a, const StampedPose& b) { return a.timestamp < b.timestamp; });
  return poses;
}

std::vector<StampedPose> read_numbered_poses(const std::string& file) {
  std::vector<StampedPose> poses;
  for_each_data_line(file, [&](std::size_t number, const std::string& line) {
    const auto fields = fields_of(line);
    if (fields.size() != 7)
      line_error(file, number, "expected 'tx ty tz qx qy qz qw', found " + std::to_string(fields.size()) + " fields");
    poses.push_back({static_cast<double>(poses.size() + 1), pose_from_fields(fields, 0, file, number)});
  });
  return poses;
}

void write_trajectory(const std::string& file, const std::vector<StampedPose>& poses) {
  OutputStream out(file);
  out << "# timestamp tx ty tz qx qy qz qw\n" << std::setprecision(17);
  for (const auto& p : poses) {
    const Eigen::Quaterniond q(p.pose.linear());
    const Eigen::Vector3d t = p.pose.translation();
    out << p.timestamp << ' ' << t.x() << ' ' << t.y() << ' ' << t.z() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z()
        << ' ' << q.w() << '\n';
  }
  out.commit();
}

std::vector<std::pair<std::size_t, std::size_t>> associate(const std::vector<double>& a, const std::vector<double>& b,
                                                          double max_difference) {
  std::vector<std::size_t> b_order(b.size());
  for (std::size_t i = 0; i < b.size(); ++i) b_order[i] = i;
  std::sort(b_order.begin(), b_order.end(), [&](std::size_t x, std::size_t y) { return b[x] < b[y]; });
  struct Candidate {
    double difference;
    std::size_t ia, ib;
  };
  // Every pair within the window is a candidate, as TUM's associate.py has it: counted
  // first, since repeated timestamps or a window far wider than the frames' spacing make
  // it n x m (15,000 poses at one timestamp ran out of memory at 3 GB).
  const auto window = [&](double t) {
    const auto lo = std::lower_bound(b_order.begin(), b_order.end(), t - max_difference,
                                     [&](std::size_t ib, double v) { return b[ib] < v; });
    const auto hi = std::upper_bound(lo, b_order.end(), t + max_difference,
                                     [&](double v, std::size_t ib) { return v < b[ib]; });
    return std::pair(lo, hi);
  };
  constexpr std::uint64_t kMaxCandidates = 20'000'000;  // ~480 MB of candidates
  std::uint64_t count = 0;
  for (const double t : a) {
    const auto [lo, hi] = window(t);
    count += static_cast<std::uint64_t>(hi - lo);
  }
  if (count > kMaxCandidates)
    throw InvalidArgument("associating timestamps: " + std::to_string(count) + " pairs lie within " +
                          std::to_string(max_difference) + " s of each other (more than " +
                          std::to_string(kMaxCandidates) + "): the timestamps repeat, or the allowed difference is "
                          "far wider than the frames' spacing");
  std::vector<Candidate> candidates;
  candidates.reserve(count);
  for (std::size_t ia = 0; ia < a.size(); ++ia) {
    const auto [lo, hi] = window(a[ia]);
    for (auto it = lo; it != hi; ++it) candidates.push_back({std::abs(a[ia] - b[*it]), ia, *it});
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& x, const Candidate& y) { return x.difference < y.difference; });
  std::vector<bool> used_a(a.size()), used_b(b.size());
  std::vector<std::pair<std::size_t, std::size_t>> matches;
  for (const auto& c : candidates) {
    if (used_a[c.ia] || used_b[c.ib]) continue;
    used_a[c.ia] = used_b[c.ib] = true;
    matches.emplace_back(c.ia, c.ib);
  }
  std::sort(matches.begin(), matches.end());
  return matches;
}

Sequence read_sequence(const std::string& directory, double max_difference) {
  const fs::path dir(directory);
  if (!fs::is_directory(dir)) throw IoError(directory + ": not a directory");
  std::optional<Intrinsics> intrinsics;
  if (fs::exists(dir / "intrinsics.txt")) intrinsics = read_intrinsics((dir / "intrinsics.txt").string());
  if (!fs::exists(dir / "depth.txt")) {
    Sequence numbered = read_numbered_layout(dir);
    numbered.intrinsics = intrinsics;
    return numbered;
  }
  const auto depth = read_timed_list((dir / "depth.txt").string());
  if (depth.empty()) throw FormatError((dir / "depth.txt").string(), std::nullopt, "lists no depth frames");
  for (std::size_t i = 1; i < depth.size(); ++i)
    if (!(depth[i].timestamp > depth[i - 1].timestamp))
      throw FormatError((dir / "depth.txt").string(), std::nullopt,
                        "timestamps must increase: frame " + std::to_string(i + 1) + " is not after frame " + std::to_string(i));
  // A listed frame that is missing fails here, naming the list's line, not minutes later.
  const auto require_files = [](const fs::path& list_file, const fs::path& base, const std::vector<TimedPath>& list) {
    for (const auto& entry : list)
      if (!fs::is_regular_file(resolve(base, entry.path)))
        line_error(list_file.string(), entry.line,
                   "frame file '" + resolve(base, entry.path) + "' " +
                       (fs::exists(resolve(base, entry.path)) ? "is not a regular file" : "does not exist"));
  };
  require_files(dir / "depth.txt", dir, depth);
  Sequence sequence;
  for (const auto& d : depth) sequence.frames.push_back({d.timestamp, resolve(dir, d.path), {}});
  if (fs::exists(dir / "rgb.txt")) {
    const auto rgb = read_timed_list((dir / "rgb.txt").string());
    require_files(dir / "rgb.txt", dir, rgb);
    std::vector<double> td, tr;
    for (const auto& d : depth) td.push_back(d.timestamp);
    for (const auto& r : rgb) tr.push_back(r.timestamp);
    const auto pairs = associate(td, tr, max_difference);
    // Colour listed but never close enough in time to a depth frame: the map would lose
    // its colours (and tracking its features) without a word.
    if (pairs.empty() && !rgb.empty())
      throw FormatError((dir / "rgb.txt").string(), std::nullopt,
                        "none of its " + std::to_string(rgb.size()) + " colour frames lies within " +
                            std::to_string(static_cast<int>(max_difference * 1000)) +
                            " ms of a depth frame (the timestamps of rgb.txt and depth.txt do not match); fix them, "
                            "or remove rgb.txt to fuse depth alone");
    for (const auto& [i, j] : pairs) sequence.frames[i].rgb_path = resolve(dir, rgb[j].path);
  }
  if (fs::exists(dir / "groundtruth.txt")) sequence.groundtruth = read_trajectory((dir / "groundtruth.txt").string());
  sequence.intrinsics = intrinsics;
  return sequence;
}

}  // namespace vola::slam
