// A LAZ (or COPC) file as a point source for vola tile: one work unit per LAZ chunk
// (chunks are independent, so any worker decodes any chunk), decoded with vola's codec
// through LasReader::decode_laz_chunk, which reads with pread and is safe from many threads.
#include "laz_points.hpp"

#include "vola/io/las.hpp"
#include "las_records.hpp"

namespace vola::tile {

namespace {

class LazPoints final : public PointSource {
 public:
  explicit LazPoints(std::unique_ptr<io::LasReader> reader) : reader_(std::move(reader)), name_(path_of(*reader_)) {
    epsg = reader_->header().epsg;
    wkt = reader_->header().wkt;
  }
  const std::string& name() const noexcept override { return name_; }
  std::uint64_t chunk_count() const noexcept override { return reader_->header().laz_chunks.size(); }
  std::uint64_t point_count() const noexcept override { return reader_->header().point_count; }
  // Coordinates alone: layered chunks (formats 6-10) decode only their XY and Z layers.
  void read_chunk(std::uint64_t chunk, std::vector<double>& xyz) const override {
    las_record_xyz(reader_->header(), decoded(chunk, true), xyz);
  }
  std::vector<AttributeSpec> attributes() const override { return io::las_attributes(reader_->header()); }
  void read_chunk_with_values(std::uint64_t chunk, std::vector<double>& xyz,
                              std::vector<std::vector<double>>& values) const override {
    las_record_points(reader_->header(), decoded(chunk, false), xyz, values);
  }

 private:
  // Chunk c's records, decoded into a buffer of this thread's (valid until its next call).
  std::span<const std::uint8_t> decoded(std::uint64_t chunk, bool coordinates_only) const {
    thread_local std::vector<std::uint8_t> records;
    reader_->decode_laz_chunk(static_cast<std::size_t>(chunk), records, coordinates_only);
    return records;
  }
  static std::string path_of(const io::LasReader& reader) { return reader.path(); }
  std::unique_ptr<io::LasReader> reader_;
  std::string name_;
};

}  // namespace

std::unique_ptr<PointSource> open_laz_points(std::unique_ptr<io::LasReader> reader) {
  return std::make_unique<LazPoints>(std::move(reader));
}

}  // namespace vola::tile
