// A point source whose chunks lose the points the per-point filter stages drop (vola
// tile --where / --crop / --crop-polygon), as each chunk is read: a stage that looks at
// one point at a time gives the same answer on a chunk as on the whole file. The stages'
// dimensions are x, y, z and the source's attribute columns, read for every chunk
// whether or not the tiles keep them.
#include <memory>
#include <string>
#include <vector>

#include "vola/error.hpp"
#include "vola/filters/dimensions.hpp"
#include "vola/filters/stages.hpp"
#include "vola/tile/point_source.hpp"

namespace vola::tile {

namespace {

class FilteredPoints final : public PointSource {
 public:
  FilteredPoints(std::unique_ptr<PointSource> source, std::vector<filters::Stage> stages)
      : source_(std::move(source)), stages_(std::move(stages)), columns_(source_->attributes()) {
    epsg = source_->epsg;
    wkt = source_->wkt;
  }
  const std::string& name() const noexcept override { return source_->name(); }
  std::uint64_t chunk_count() const noexcept override { return source_->chunk_count(); }
  // The points offered to the filters (the count before them is all a source knows).
  std::uint64_t point_count() const noexcept override { return source_->point_count(); }
  std::vector<AttributeSpec> attributes() const override { return columns_; }
  void read_chunk(std::uint64_t chunk, std::vector<double>& xyz) const override {
    thread_local std::vector<std::vector<double>> values;
    read_chunk_with_values(chunk, xyz, values);
  }
  void read_chunk_with_values(std::uint64_t chunk, std::vector<double>& xyz,
                              std::vector<std::vector<double>>& values) const override {
    thread_local PointCloud cloud;
    source_->read_chunk_with_values(chunk, cloud.xyz, values);
    cloud.attributes.resize(values.size());
    for (std::size_t a = 0; a < values.size(); ++a) {
      cloud.attributes[a].name = columns_[a].name;
      cloud.attributes[a].type = columns_[a].type;
      cloud.attributes[a].values.swap(values[a]);
    }
    const std::vector<bool> keep = filters::per_point_mask(stages_, cloud);
    xyz.clear();
    for (auto& column : values) column.clear();
    for (std::size_t i = 0; i < keep.size(); ++i) {
      if (!keep[i]) continue;
      xyz.insert(xyz.end(), cloud.xyz.begin() + static_cast<std::ptrdiff_t>(3 * i),
                 cloud.xyz.begin() + static_cast<std::ptrdiff_t>(3 * i + 3));
      for (std::size_t a = 0; a < values.size(); ++a) values[a].push_back(cloud.attributes[a].values[i]);
    }
  }

 private:
  std::unique_ptr<PointSource> source_;
  std::vector<filters::Stage> stages_;
  std::vector<AttributeSpec> columns_;
};

}  // namespace

std::unique_ptr<PointSource> filtered(std::unique_ptr<PointSource> source, const std::vector<std::string>& specs) {
  std::vector<filters::Stage> stages = filters::parse_stages(specs);
  for (const filters::Stage& s : stages)
    if (!s.per_point()) {
      // hag's column has no LAS field: a LAS output would drop it.
      const std::string out = s.kind == filters::Stage::Kind::hag ? "OUT.ply" : "OUT.laz";
      throw OptionError("filters", "'" + s.spec +
                                       "' needs each point's neighbours, which vola tile reads chunk by chunk; "
                                       "run it first with vola translate IN " +
                                       out + " --filter ..., then tile " + out);
    }
  // The filters see x, y, z and the columns the tiles are made with, not every field of
  // the file: a field the file has but tile does not read is named as such, up front
  // (the points were said to have no such dimension, though `vola info` lists it).
  PointCloud columns;
  for (const AttributeSpec& spec : source->attributes()) columns.attributes.push_back({spec.name, spec.type, {}, {}});
  for (const filters::Stage& s : stages) {
    if (!s.expression) continue;
    for (const std::string& name : s.expression->dimensions())
      if (!filters::find_dimension(columns, name))
        throw OptionError("filters", "'" + s.spec + "': vola tile's filters see x, y, z and the columns it keeps (" +
                                         filters::dimension_list(columns) + "), not '" + name + "' of " +
                                         source->name() + "; filter on it first with vola translate IN OUT.laz " +
                                         "--where ..., then tile OUT.laz");
  }
  return std::make_unique<FilteredPoints>(std::move(source), std::move(stages));
}

}  // namespace vola::tile
