#include "vola/tile/point_source.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include "vola/error.hpp"
#include "vola/io/input.hpp"
#include "vola/io/las.hpp"
#include "las_records.hpp"
#include "laz_points.hpp"
#include "vola/synth/city.hpp"

namespace vola::tile {

namespace {

// Records are read with pread into a buffer of the reading thread's, never mapped: a
// file cut while it is tiled is then a short read (an IoError naming it), not SIGBUS,
// and the page cache keeps the file's pages out of the process (as LasReader does; a
// map also cost a TLB miss and a page fault every few pages).
class LasPoints final : public PointSource {
 public:
  LasPoints(const std::string& path, std::size_t chunk_points) : name_(path), chunk_points_(chunk_points) {
    const io::LasReader reader(path);  // checks the header, the VLRs and that the records fit the file
    header_ = reader.header();
    epsg = header_.epsg;
    wkt = header_.wkt;
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) throw IoError(path + ": cannot open (" + std::strerror(errno) + ")");
  }
  ~LasPoints() override {
    if (fd_ >= 0) ::close(fd_);
  }
  LasPoints(const LasPoints&) = delete;
  LasPoints& operator=(const LasPoints&) = delete;

  const std::string& name() const noexcept override { return name_; }
  std::uint64_t chunk_count() const noexcept override {
    return (header_.point_count + chunk_points_ - 1) / chunk_points_;
  }
  std::uint64_t point_count() const noexcept override { return header_.point_count; }

  void read_chunk(std::uint64_t chunk, std::vector<double>& xyz) const override {
    // In batches that stay in cache, so that the buffer stays small however large the chunk.
    const auto [first, n] = range_of(chunk);
    const std::uint64_t batch = std::max<std::uint64_t>(1, io::kLasRecordBatchBytes / header_.record_length);
    xyz.clear();
    thread_local std::vector<double> part;
    for (std::uint64_t done = 0; done < n; done += batch) {
      las_record_xyz(header_, records(first + done, std::min(batch, n - done)), part);
      xyz.insert(xyz.end(), part.begin(), part.end());
    }
  }

  std::vector<AttributeSpec> attributes() const override { return io::las_attributes(header_); }

  void read_chunk_with_values(std::uint64_t chunk, std::vector<double>& xyz,
                              std::vector<std::vector<double>>& values) const override {
    const auto [first, n] = range_of(chunk);
    las_record_points(header_, records(first, n), xyz, values);
  }

 private:
  // Chunk c's first point and number of points.
  std::pair<std::uint64_t, std::uint64_t> range_of(std::uint64_t chunk) const {
    const std::uint64_t first = chunk * chunk_points_;
    return {first, first < header_.point_count ? std::min<std::uint64_t>(chunk_points_, header_.point_count - first) : 0};
  }
  // Records [first, first + n), read into this thread's buffer (valid until its next call).
  std::span<const std::uint8_t> records(std::uint64_t first, std::uint64_t n) const {
    thread_local std::vector<std::uint8_t> buffer;
    const std::size_t bytes = static_cast<std::size_t>(n * header_.record_length);
    if (buffer.size() < bytes) buffer.resize(bytes);
    std::uint64_t offset = header_.offset_to_points + first * header_.record_length;
    for (std::size_t done = 0; done < bytes;) {
      const ssize_t got = ::pread(fd_, buffer.data() + done, bytes - done, static_cast<off_t>(offset));
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0)
        throw IoError(name_ + ": byte " + std::to_string(offset) + ": cannot read the point records (" +
                      (got < 0 ? std::string(std::strerror(errno)) : "the file is shorter than its header says: cut while tiled?") +
                      ")");
      done += static_cast<std::size_t>(got);
      offset += static_cast<std::uint64_t>(got);
    }
    return {buffer.data(), bytes};
  }

  std::string name_;
  std::size_t chunk_points_;
  io::LasHeader header_;
  int fd_ = -1;
};

class WholeFilePoints final : public PointSource {
 public:
  WholeFilePoints(const std::string& path, bool attributes) : name_(path) {
    io::InputOptions options;
    options.attributes = attributes;
    io::Input input = io::read_input(path, "auto", options);
    if (input.is_mesh() || input.grid || input.terrain)
      throw InvalidArgument(path + ": vola tile takes point clouds (LAS, XYZ/TXT/CSV, PLY, PCD, NPY, KITTI); convert " +
                            input.format + " input with vola convert");
    xyz_ = std::move(input.cloud.xyz);
    for (auto& column : input.cloud.attributes) {
      specs_.push_back({column.name, column.type, column.reduction});
      values_.push_back(std::move(column.values));
    }
    epsg = input.epsg;
    wkt = input.wkt;
  }
  const std::string& name() const noexcept override { return name_; }
  std::uint64_t chunk_count() const noexcept override { return 1; }
  std::uint64_t point_count() const noexcept override { return xyz_.size() / 3; }
  void read_chunk(std::uint64_t, std::vector<double>& xyz) const override { xyz = xyz_; }
  std::vector<AttributeSpec> attributes() const override { return specs_; }
  void read_chunk_with_values(std::uint64_t, std::vector<double>& xyz,
                              std::vector<std::vector<double>>& values) const override {
    xyz = xyz_;
    values = values_;
  }

 private:
  std::string name_;
  std::vector<double> xyz_;
  std::vector<AttributeSpec> specs_;
  std::vector<std::vector<double>> values_;
};

class GeneratedSurvey final : public PointSource {
 public:
  explicit GeneratedSurvey(const SurveyOptions& o) : options_(o) {
    if (!(o.density > 0.0) || !std::isfinite(o.density)) throw InvalidArgument("survey density must be positive");
    if (o.points == 0) throw InvalidArgument("a generated survey needs at least one point");
    const double side = std::sqrt(static_cast<double>(o.points) / o.density);
    per_side_ = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::ceil(side / kBlock)));
    name_ = "generated survey (" + std::to_string(o.points) + " points, " + std::to_string(per_side_) + "x" +
            std::to_string(per_side_) + " blocks of 200 m, seed " + std::to_string(o.seed) + ")";
  }
  const std::string& name() const noexcept override { return name_; }
  std::uint64_t chunk_count() const noexcept override { return per_side_ * per_side_; }
  std::uint64_t point_count() const noexcept override { return options_.points; }

  void read_chunk(std::uint64_t chunk, std::vector<double>& xyz) const override {
    const std::uint64_t blocks = chunk_count();
    synth::CityOptions city;
    city.points = options_.points / blocks + (chunk < options_.points % blocks ? 1 : 0);
    city.seed = options_.seed * 0x9E3779B97F4A7C15ull + chunk;  // one independent stream per block
    city.size = kBlock;
    city.origin = {options_.origin[0] + kBlock * static_cast<double>(chunk % per_side_),
                   options_.origin[1] + kBlock * static_cast<double>(chunk / per_side_), options_.origin[2]};
    xyz.clear();
    xyz.reserve(3 * city.points);
    synth::generate_city(city, [&](const synth::CityPoint& p) {
      xyz.push_back(p.x);
      xyz.push_back(p.y);
      xyz.push_back(p.z);
    });
  }

 private:
  static constexpr double kBlock = 200.0;
  SurveyOptions options_;
  std::uint64_t per_side_ = 1;
  std::string name_;
};

}  // namespace

std::unique_ptr<PointSource> open_las_points(const std::string& path, std::size_t chunk_points) {
  if (chunk_points == 0) throw InvalidArgument("chunk size must be positive");
  auto reader = std::make_unique<io::LasReader>(path);  // checks the header, the VLRs and the records' extent
  if (reader->header().compressed()) return open_laz_points(std::move(reader));
  return std::make_unique<LasPoints>(path, chunk_points);
}

std::unique_ptr<PointSource> open_file_points(const std::string& path, bool attributes) {
  return std::make_unique<WholeFilePoints>(path, attributes);
}

std::unique_ptr<PointSource> generated_survey(const SurveyOptions& options) {
  return std::make_unique<GeneratedSurvey>(options);
}

}  // namespace vola::tile
