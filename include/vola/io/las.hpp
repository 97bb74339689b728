// ASPRS LAS 1.0-1.4, point data record formats 0-10, read natively from the
// specification (no LAS library is packaged for Debian 12). Streaming: points come in
// chunks of a chosen size, so a file larger than memory can be read in bounded memory.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <fstream>
#include <functional>
#include <future>
#include <memory>
#include <span>
#include <optional>
#include <string>
#include <vector>

#include "vola/builder.hpp"
#include "vola/io/copc.hpp"
#include "vola/io/laz.hpp"
#include "vola/stream_builder.hpp"
#include "vola/voxel_reducer.hpp"

namespace vola::io {

struct LasVlr {
  std::string user_id;
  std::uint16_t record_id = 0;
  std::string description;
  bool extended = false;  // an EVLR (LAS 1.4)
  std::uint64_t offset = 0;  // file offset of the record's data
  std::uint64_t length = 0;  // bytes of data in the file
  std::vector<std::uint8_t> data;  // the data (of an EVLR only when it describes the points)
};

// One "extra bytes" field (LASF_Spec record 4) of each point record.
struct LasExtraField {
  std::string name;
  std::uint8_t data_type = 0;  // 1 u8, 2 i8, 3 u16, 4 i16, 5 u32, 6 i32, 7 u64, 8 i64, 9 f32, 10 f64; 0 raw bytes
  std::uint32_t offset = 0;    // byte offset inside the record
  std::uint32_t size = 0;
  double scale = 1.0, add = 0.0;
  // Options bit 0: this stored value (before scale and offset) means "no data"; such
  // values are read as NaN (a point without a value), which means, max, min and
  // summaries skip.
  std::optional<double> no_data;
};

struct LasHeader {
  std::uint8_t version_major = 1, version_minor = 2;
  std::string system_identifier, generating_software;
  std::uint16_t header_size = 227;
  std::uint32_t offset_to_points = 0;
  std::uint8_t point_format = 0;
  std::uint16_t record_length = 20;
  std::uint64_t point_count = 0;  // the 1.4 64-bit count when present and non-zero
  std::array<double, 3> scale{1, 1, 1}, offset{0, 0, 0}, min{}, max{};
  std::uint16_t global_encoding = 0;
  std::vector<LasVlr> vlrs;  // VLRs and EVLRs with their data
  std::vector<LasExtraField> extra_fields;
  std::optional<std::uint32_t> epsg;  // from the GeoKeyDirectory (not user-defined 32767)
  std::string wkt;                    // OGC WKT record (LASF_Projection 2112), if any
  // LAZ: the laszip VLR (the point records are compressed; point_format is without the
  // compression bits) and where each chunk of points lies.
  std::optional<laz::LaszipInfo> laszip;
  std::vector<laz::ChunkEntry> laz_chunks;
  std::optional<CopcHierarchy> copc;  // a COPC file's octree of chunks
  bool compressed() const noexcept { return laszip.has_value(); }
  bool has_rgb() const noexcept;
  bool has_gps_time() const noexcept;
  bool extended_format() const noexcept { return point_format >= 6; }
  std::string version() const { return std::to_string(version_major) + "." + std::to_string(version_minor); }
  // Decimals that print axis `axis`'s coordinates (offset + scale * n) as the file means
  // them: the fewest for which the scale and the offset are whole multiples of 10^-d
  // (0.00025 takes 5, 0.01 with offset 7350.194653 takes 6; a negative scale as its
  // magnitude), at most 12, and no more than a double's 15 significant digits carry at
  // the axis's magnitude (header bounds and offset).
  int coordinate_decimals(int axis) const noexcept;
  // The most of the three: one precision for every coordinate of a point file.
  int coordinate_decimals() const noexcept;
};

// Structure of arrays for one chunk of points.
struct LasChunk {
  std::vector<double> xyz;  // x0 y0 z0 x1 ...
  std::vector<std::uint16_t> intensity;
  std::vector<std::uint8_t> return_number, number_of_returns, classification, user_data;
  std::vector<std::uint16_t> point_source_id;
  std::vector<double> gps_time;            // empty without GPS time
  std::vector<std::uint16_t> red, green, blue;  // empty without RGB
  std::vector<std::vector<double>> extra;  // one vector per LasHeader::extra_fields entry
  std::size_t size() const noexcept { return xyz.size() / 3; }
  void clear();
};

// Point records (header.record_length bytes each) decoded and appended to `chunk`.
void decode_las_records(const LasHeader& header, std::span<const std::uint8_t> records, LasChunk& chunk);

class LasReader {
 public:
  // Reads and checks the header and (E)VLRs, and for LAZ the laszip VLR and the chunk
  // table. Throws FormatError with file and offset on anything malformed.
  explicit LasReader(const std::string& path);
  // The same over bytes in memory (copied); `name` labels errors.
  LasReader(std::span<const std::uint8_t> bytes, const std::string& name);
  ~LasReader();
  LasReader(const LasReader&) = delete;
  LasReader& operator=(const LasReader&) = delete;
  const LasHeader& header() const noexcept { return header_; }
  const std::string& path() const noexcept { return path_; }
  // Reads up to `max_points` points into `chunk` (cleared first); 0 at the end. With
  // `xyz_only`, only the coordinates are decoded.
  std::size_t read(LasChunk& chunk, std::size_t max_points, bool xyz_only = false);
  // Up to `max_points` undecoded point records, header().record_length bytes each (valid
  // until the next read); empty at the end. A file is read with pread() into a buffer
  // the reader reuses (as large as the largest request): the file's pages stay in the
  // page cache, not in the process's memory, so a file larger than memory reads in
  // bounded memory. Requests of ~kLasRecordBatchBytes keep the records in cache.
  std::span<const std::uint8_t> read_records(std::size_t max_points);
  std::uint64_t points_read() const noexcept { return next_; }
  // The points read() and read_records() give in all: the header's count, or that of the
  // COPC nodes selected below.
  std::uint64_t points_total() const noexcept { return points_total_; }
  // Bytes read from the file so far (header, tables and point data).
  std::uint64_t bytes_read() const noexcept { return bytes_read_; }

  // COPC: read only the octree nodes down to `max_level` (0 = the root) whose cube meets
  // `region`, in file order; the points of the others are never read (nor their bytes).
  // Throws InvalidArgument for a max_level on a file that is not COPC; a region alone on
  // other files selects everything (they have no index to skip by). Rewinds.
  void select_copc_nodes(const std::optional<Box>& region, std::optional<int> max_level);
  // The max_level of the last selection.
  std::optional<int> copc_level() const noexcept { return copc_level_; }
  // Back to the first point (for a second pass).
  void rewind();
  // LAZ: read_records() may give records whose fields other than X, Y and Z are not
  // decoded (layered chunks, point formats 6-10, then decode only the layers of their
  // coordinates; the other fields hold values of earlier points), for passes that use
  // only the coordinates. Off by default; changing it rewinds.
  void set_coordinates_only(bool on);

  // LAZ: the next pass that reads every record keeps them, as decoded, in an unlinked
  // temporary file ($TMPDIR, else /tmp: as many bytes as the LAS file would take); after
  // it, read_records() reads them back from there (pread, as from a LAS file) instead of
  // decoding the chunks again. For conversions that read the records more than once.
  // Until that pass is complete, set_coordinates_only() is ignored (kept records are
  // whole). A file that cannot be made or written (a full disk) is given up on quietly:
  // the passes decode, as without it. Selecting COPC nodes starts the kept records over.
  // Returns whether a file was made. Rewinds.
  bool keep_decoded_records();
  // Whether read_records() now reads kept records (the pass that kept them is complete).
  bool reads_kept_records() const noexcept { return kept_complete_; }

  // LAZ: chunk `chunk` of header().laz_chunks decoded into `records` (resized to its
  // point count x record_length). Safe to call from many threads at once on a file
  // opened by path; throws FormatError naming the chunk and its byte offset.
  // With coordinates_only, only X, Y and Z are decoded exactly (see set_coordinates_only).
  void decode_laz_chunk(std::size_t chunk, std::vector<std::uint8_t>& records, bool coordinates_only = false) const;

 private:
  std::string path_;
  void read_header();
  void fetch(std::uint64_t offset, std::uint64_t size, std::uint8_t* out) const;
  // LAZ: a batch of chunks decoded together, one per thread (records[i]: chunk
  // chunk_order_[first + i]).
  struct LazBatch {
    std::vector<std::vector<std::uint8_t>> records;
    std::size_t first = 0, count = 0;
  };
  std::span<const std::uint8_t> read_laz_records(std::size_t max_points);
  void keep(std::span<const std::uint8_t> records, std::uint64_t first);
  std::span<const std::uint8_t> read_kept_records(std::size_t max_points);
  void decode_laz_batch(LazBatch& batch, std::size_t begin) const;
  void settle_laz_prefetch() noexcept;

  std::shared_ptr<const int> fd_;            // a regular file, open for pread()
  std::vector<std::uint8_t> owned_;          // the in-memory constructor's copy
  std::span<const std::uint8_t> bytes_;      // owned_ (empty when read from a file)
  std::uint64_t file_size_ = 0;
  LasHeader header_;
  std::uint64_t next_ = 0;
  std::vector<std::uint8_t> buffer_;
  // LAZ: the batch being read (chunk batch_chunk_ of it, from point batch_point_), and
  // the next one, decoded ahead on other threads (prefetch_) while this one is read.
  LazBatch current_, ahead_;
  std::size_t batch_chunk_ = 0;
  std::uint64_t batch_point_ = 0;
  std::future<void> prefetch_;
  std::vector<std::size_t> chunk_order_;      // the chunks read, in file order (all, or the selected COPC nodes)
  std::uint64_t points_total_ = 0;
  std::optional<int> copc_level_;
  bool coordinates_only_ = false;
  mutable std::atomic<std::uint64_t> bytes_read_{0};
  // keep_decoded_records(): the temporary file, the records kept in it (the first
  // kept_points_), and whether they are all there.
  std::shared_ptr<const int> kept_fd_;
  std::uint64_t kept_points_ = 0;
  bool kept_complete_ = false;
};

// Point records from a LAS or LAZ file into a LAS (.las) or LAZ (.laz, LASzip compressor 2
// for point formats 0-3, 3 for 6-8) file, record for record and in order: the header,
// every VLR and EVLR but those of the input's compression (laszip, COPC), so the CRS,
// extra bytes, GPS times and returns all carry over. The output's kind follows its
// extension; it is written under a temporary name and renamed when complete.
// progress(done, total) counts points.
// With `edits`, only the records kept[i] (input indices, increasing) are written, with
// the classification of points.attributes' "classification" column (point i of
// `points` is record kept[i]), and the header's point counts, counts by return and
// bounds follow them.
struct LasRecordEdits {
  const std::vector<std::uint64_t>& kept;
  const PointCloud& points;
};
void translate_las(const std::string& input, const std::string& output,
                   const std::function<void(std::uint64_t, std::uint64_t)>& progress = {},
                   const std::optional<LasRecordEdits>& edits = std::nullopt);

// Bytes of records worth reading at once: a batch that stays in L2 while its keys or
// fields are decoded (a pread() of it from the page cache is a copy through the
// kernel's huge-page direct map; reading a memory-mapped file instead costs a TLB miss
// and a page fault every few pages, and was 3x slower).
constexpr std::size_t kLasRecordBatchBytes = std::size_t{256} << 10;

// The whole file as a point cloud with the attribute columns vola keeps from LAS:
// red/green/blue (mean), intensity (mean), classification (majority), height (mean z),
// number_of_returns (max), extra-bytes fields by name (io::default_reduction); and, with
// `payload`, the reference's 7-byte payload word per point (FORMAT.md section 8).
PointCloud las_points(LasReader& reader, bool attributes, bool payload,
                      const std::function<void(std::uint64_t, std::uint64_t)>& progress = {});

// The attribute columns vola keeps from a LAS file, and their per-point values for a
// chunk (one vector per column, in the same order).
std::vector<AttributeSpec> las_attributes(const LasHeader& header);
void las_attribute_values(const LasHeader& header, const LasChunk& chunk, std::vector<std::vector<double>>& values);
// The same values straight from undecoded point records (LasReader::read_records): those
// of records[index[j] * record_length] into values[a][j] (resized to index.size()).
void las_record_attribute_values(const LasHeader& header, const std::uint8_t* records,
                                 std::span<const std::uint32_t> index, std::vector<std::vector<double>>& values);
// Where las_record_attribute_values finds each value in a record, for
// VoxelReducer::add_records (the same order and decoding). False when a column cannot
// be described so (an extra field of raw bytes): use the values then.
bool las_record_fields(const LasHeader& header, std::vector<RecordField>& fields);
// The reference's payload word per point.
void las_payloads(const LasHeader& header, const LasChunk& chunk, std::vector<std::uint64_t>& payloads);

// The file straight into a tree in memory bounded by the voxels, not the points: the
// occupancy through a vola::StreamBuilder, one pass for the bounds (unless options.bbox
// is set; skipped when the header's box resolves to the same grid), one to build; with
// attribute columns, one more pass over the records into a vola::VoxelReducer (one row
// of partials per voxel, columns bit-identical to vola::build's over the same points;
// on vola::thread_count() threads, each reducing the voxels of its part of the ranks);
// with payloads, chunks of `chunk_points` points (~100 bytes each) reduced and merged in
// the StreamBuilder. Resolves `options` (depth, voxel size, origin) like vola::build.
// chunk_points 0 (the default): kLasChunkPoints with attributes or payloads,
// kLasKeyChunkPoints occupancy only (8 bytes a point: 16 + 16 MB of chunk buffers).
// A larger chunk's sorted blocks repeat less of the runs already built (fewer unions),
// a smaller one touches less fresh memory, whose page faults and zeroing are costly on
// a VM: 2M points measured best (1e7 random-order survey 0.46 s, 88 MiB; 2e8 strip
// survey 3.7 s, 183 MiB; 4M points: 0.47 s, 125 MiB; 4.1 s, 239 MiB).
constexpr std::size_t kLasChunkPoints = std::size_t{1} << 20;
constexpr std::size_t kLasKeyChunkPoints = std::size_t{1} << 21;
Tree build_las(LasReader& reader, const BuildOptions& options, bool attributes, bool payload, BuildReport* report,
               const std::function<void(std::uint64_t, std::uint64_t)>& progress = {},
               std::size_t chunk_points = 0);

}  // namespace vola::io
