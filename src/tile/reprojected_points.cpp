// A point source whose chunks are moved into another CRS as they are read (vola tile
// --target-crs). Chunks are read by many tile workers at once and a PROJ object serves
// one thread at a time, so each read borrows a single-threaded transformation from a
// small pool (as many as workers ever read at once), made the first time one is short.
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "vola/geo/crs.hpp"
#include "vola/tile/point_source.hpp"

namespace vola::tile {

namespace {

class ReprojectedPoints final : public PointSource {
 public:
  ReprojectedPoints(std::unique_ptr<PointSource> source, const std::string& from, const std::string& to)
      : source_(std::move(source)), from_(from), to_(to) {
    idle_.push_back(std::make_unique<geo::Reprojection>(from_, to_, 1));  // fails now for a CRS PROJ cannot do
    wkt = geo::crs_wkt(to_);
    epsg = geo::epsg_from_wkt(wkt);
    const std::vector<AttributeSpec> columns = source_->attributes();
    for (std::size_t a = 0; a < columns.size(); ++a)
      if (columns[a].name == "height") height_ = a;
  }
  const std::string& name() const noexcept override { return source_->name(); }
  std::uint64_t chunk_count() const noexcept override { return source_->chunk_count(); }
  std::uint64_t point_count() const noexcept override { return source_->point_count(); }
  void read_chunk(std::uint64_t chunk, std::vector<double>& xyz) const override {
    source_->read_chunk(chunk, xyz);
    transform(xyz);
  }
  std::vector<AttributeSpec> attributes() const override { return source_->attributes(); }
  void read_chunk_with_values(std::uint64_t chunk, std::vector<double>& xyz,
                              std::vector<std::vector<double>>& values) const override {
    source_->read_chunk_with_values(chunk, xyz, values);
    if (height_ && *height_ < values.size()) {  // the height moves as its point's z would
      thread_local std::vector<double> at;
      at = xyz;
      for (std::size_t i = 0; i < values[*height_].size(); ++i) at[3 * i + 2] = values[*height_][i];
      transform(at);
      for (std::size_t i = 0; i < values[*height_].size(); ++i) values[*height_][i] = at[3 * i + 2];
    }
    transform(xyz);
  }

 private:
  void transform(std::vector<double>& xyz) const {
    std::unique_ptr<geo::Reprojection> reprojection = borrow();
    try {
      reprojection->transform(xyz);
    } catch (...) {
      give_back(std::move(reprojection));
      throw;
    }
    give_back(std::move(reprojection));
  }

  std::unique_ptr<geo::Reprojection> borrow() const {
    {
      const std::lock_guard lock(mutex_);
      if (!idle_.empty()) {
        auto r = std::move(idle_.back());
        idle_.pop_back();
        return r;
      }
    }
    return std::make_unique<geo::Reprojection>(from_, to_, 1);
  }
  void give_back(std::unique_ptr<geo::Reprojection> r) const {
    const std::lock_guard lock(mutex_);
    idle_.push_back(std::move(r));
  }

  std::unique_ptr<PointSource> source_;
  std::string from_, to_;
  std::optional<std::size_t> height_;  // the source's `height` column
  mutable std::mutex mutex_;
  mutable std::vector<std::unique_ptr<geo::Reprojection>> idle_;
};

}  // namespace

std::unique_ptr<PointSource> reprojected(std::unique_ptr<PointSource> source, const std::string& from,
                                         const std::string& to) {
  return std::make_unique<ReprojectedPoints>(std::move(source), from, to);
}

}  // namespace vola::tile
