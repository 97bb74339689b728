#include "vola/tile/tile_inputs.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "vola/crs_rules.hpp"
#include "vola/error.hpp"
#include "vola/geo/crs.hpp"

namespace vola::tile {

namespace {

// Every input stays open while the tiles are made, and a survey comes as thousands of
// files: more than the usual soft limit of 1024 descriptors failed with "Too many open
// files". The soft limit is raised towards the hard one (what `ulimit -n` would do) when
// the inputs need it; beyond the hard limit the reader's error says so.
void allow_open_files(std::size_t inputs) {
  constexpr rlim_t kSpare = 256;  // spill files, plugins, GDAL, the output
  rlimit limit{};
  if (getrlimit(RLIMIT_NOFILE, &limit) != 0) return;
  const rlim_t wanted = static_cast<rlim_t>(inputs) + kSpare;
  if (limit.rlim_cur == RLIM_INFINITY || limit.rlim_cur >= wanted) return;
  limit.rlim_cur = limit.rlim_max == RLIM_INFINITY ? wanted : std::min(wanted, limit.rlim_max);
  setrlimit(RLIMIT_NOFILE, &limit);
}

std::unique_ptr<PointSource> open_source(const std::string& path, std::size_t chunk_points, bool attributes) {
  // Readers below (GDAL's above all) would open a directory or a /vsicurl/ URL as well.
  std::error_code error;
  if (!std::filesystem::exists(path, error))  // as every reader says it (an IoError, as vola convert's)
    throw IoError(path + ": cannot open: No such file or directory");
  if (!std::filesystem::is_regular_file(path, error))
    throw InvalidArgument(path + ": not a regular file (inputs are point files on this machine)");
  std::string ext = path.substr(std::min(path.size(), path.rfind('.') == std::string::npos ? path.size() : path.rfind('.')));
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".las" || ext == ".laz") return open_las_points(path, chunk_points);
  return open_file_points(path, attributes);
}

// With a target CRS, every input moved from its own CRS (assign_crs, else what it says)
// into the target as it is read: inputs in different CRSs then tile together.
void reproject_sources(const TileInputs& in, std::vector<std::unique_ptr<PointSource>>& sources) {
  if (in.target_crs.empty()) return;
  const std::string to = crs_definition_of(in.target_crs);
  for (auto& s : sources) {
    std::string from = !in.assign_crs.empty() ? crs_definition_of(in.assign_crs) : !s->wkt.empty() ? s->wkt : "";
    if (from.empty() && s->epsg) from = "EPSG:" + std::to_string(*s->epsg);
    if (from.empty()) throw OptionError("assign_crs", s->name() + " states no CRS to reproject from; name it with `assign_crs`");
    s = reprojected(std::move(s), from, to);
  }
}

// The CRS every tile carries: `assign` (empty: what the inputs say; they must agree).
// Tiles of a geographic CRS (voxels of degrees by units of height) only when allowed.
void resolve_tile_crs(const std::string& assign, bool allow_geographic,
                      const std::vector<std::unique_ptr<PointSource>>& sources, TileOptions& options) {
  std::vector<StatedCrs> stated;
  for (const auto& s : sources) stated.push_back({s->name(), s->epsg, s->wkt});
  const ResolvedCrs crs = resolve_crs(stated, assign);
  if (!allow_geographic && !crs.wkt.empty() && is_geographic_crs(crs.wkt)) {
    std::string name = "a geographic CRS";
    try {
      name = geo::describe_crs(crs.wkt, geo::EpsgLookup::own_id_only).name + ", a geographic CRS";
    } catch (const Error&) {
      // The words above say enough.
    }
    throw OptionError("", sources.front()->name() + (sources.size() > 1 ? " and the other inputs are" : " is") +
                              " in " + name +
                              ": tiles and voxels would be degrees of longitude and latitude by "
                              "units of height, not cubes; give `target_crs` (a projected CRS such as UTM), or "
                              "`allow_geographic` to tile in degrees anyway");
  }
  // The index's footprints go through GDAL, whose PROJ contexts would open the file.
  if (const std::string named = geo::crs_file_reference(crs.wkt); !named.empty())
    throw InvalidArgument("the inputs' CRS embeds a PROJ string that names a file ('" + named.substr(0, 80) +
                          "'); GDAL would open it to place the tile footprints, so this CRS is refused (name the "
                          "CRS with `assign_crs`, or reproject with `target_crs`)");
  options.epsg = crs.epsg;
  options.crs_wkt = crs.wkt;
}

// What the user should know about the inputs' CRSs: assign_crs on an input that says
// another CRS relabels its coordinates (with target_crs too: it is reprojected from the
// label, and a UTM survey given a state-plane label moved by kilometres without a word);
// with target_crs, heights it leaves in another unit than x and y.
std::vector<std::string> crs_warnings(const TileInputs& in, const std::vector<std::unique_ptr<PointSource>>& sources) {
  std::vector<std::string> warnings;
  for (const auto& s : sources) {
    const std::string said = !s->wkt.empty() ? s->wkt : s->epsg ? "EPSG:" + std::to_string(*s->epsg) : "";
    if (in.assign_crs.empty() || said.empty()) continue;
    try {
      if (relabels_horizontally(said, crs_definition_of(in.assign_crs)))
        warnings.push_back(s->name() + " states " + geo::crs_summary(geo::describe_crs(said)) + "; `assign_crs` " +
                           in.assign_crs.substr(0, 60) + " relabels its coordinates without moving them" +
                           (in.target_crs.empty() ? " (to move them, give `target_crs`)"
                                                  : ", and `target_crs` reprojects them from that label, not from "
                                                    "the CRS the file states"));
    } catch (const Error&) {
      // A CRS PROJ cannot read: resolve_tile_crs reports what matters.
    }
  }
  if (in.target_crs.empty()) return warnings;
  for (const auto& s : sources) {  // heights a reprojection leaves in another unit
    const std::string said = !in.assign_crs.empty() ? in.assign_crs
                             : !s->wkt.empty()      ? s->wkt
                             : s->epsg              ? "EPSG:" + std::to_string(*s->epsg)
                                                    : "";
    if (said.empty()) continue;
    if (const std::string heights = unconverted_heights(said, in.target_crs); !heights.empty())
      warnings.push_back(s->name() + ": " + heights);
  }
  return warnings;
}

}  // namespace

std::vector<const PointSource*> OpenedInputs::views() const {
  std::vector<const PointSource*> out;
  for (const auto& s : sources) out.push_back(s.get());
  return out;
}

OpenedInputs open_inputs(const TileInputs& in, TileOptions& options) {
  if (in.inputs.empty() && in.generate_survey == 0)
    throw OptionError("inputs", "no input: give point files or `generate_survey` N");
  if (!in.assign_crs.empty()) resolve_crs({}, in.assign_crs);  // an unknown CRS fails before any work
  OpenedInputs out;
  const std::size_t chunk_points = in.chunk_points ? in.chunk_points : chunk_points_for(options);
  allow_open_files(in.inputs.size());
  for (const std::string& path : in.inputs) {
    try {
      out.sources.push_back(open_source(path, chunk_points, options.attributes));
    } catch (const IoError& e) {
      if (std::string(e.what()).find(std::strerror(EMFILE)) == std::string::npos) throw;  // not the limit
      throw IoError(std::string(e.what()) + ": vola tile keeps its " + std::to_string(in.inputs.size()) +
                    " inputs open at once, more than this process may open; raise the limit (ulimit -n, up to " +
                    "its hard limit, ulimit -Hn) or tile fewer files at a time");
    }
  }
  if (in.generate_survey) {
    SurveyOptions survey = in.survey;
    survey.points = in.generate_survey;
    out.sources.push_back(generated_survey(survey));
  }
  if (!in.filters.empty())
    for (auto& s : out.sources) s = filtered(std::move(s), in.filters);
  out.warnings = crs_warnings(in, out.sources);
  // Filters run in each input's own CRS, before any reprojection: one box or polygon
  // cannot crop inputs in different CRSs (a crop in UTM metres dropped a whole file in
  // Oregon feet, exit 0).
  if (in.assign_crs.empty() && !in.target_crs.empty() &&
      std::any_of(in.filters.begin(), in.filters.end(),
                  [](const std::string& f) { return f.rfind("crop:", 0) == 0 || f.rfind("polygon:", 0) == 0; })) {
    const auto said = [](const PointSource& s) {
      return !s.wkt.empty() ? s.wkt : s.epsg ? "EPSG:" + std::to_string(*s.epsg) : std::string();
    };
    for (const auto& s : out.sources) {
      const PointSource& first = *out.sources.front();
      bool same = said(*s) == said(first);
      try {
        same = same || (!said(*s).empty() && !said(first).empty() && geo::same_crs(said(*s), said(first)));
      } catch (const Error&) {
        // A CRS PROJ cannot read: resolve_tile_crs reports what matters.
      }
      if (same) continue;
      out.warnings.push_back("the crop runs in each input's own CRS, before the reprojection to " + in.target_crs +
                             ", and " + first.name() + " and " + s->name() +
                             " are in different CRSs: one box or polygon cannot crop both (crop each with vola "
                             "translate, or reproject them to one CRS, first)");
      break;
    }
  }
  reproject_sources(in, out.sources);
  // After a reprojection every source states the target.
  resolve_tile_crs(in.target_crs.empty() ? in.assign_crs : std::string(), in.allow_geographic, out.sources, options);
  // Heights in another unit than x and y (US feet under metres): as vola convert says it.
  const std::string crs = !options.crs_wkt.empty() ? options.crs_wkt
                          : options.epsg           ? "EPSG:" + std::to_string(*options.epsg)
                                                   : std::string();
  if (!crs.empty())
    if (std::string mixed = mixed_units(crs); !mixed.empty()) out.warnings.push_back(std::move(mixed));
  for (const auto& s : out.sources) out.points += s->point_count();
  return out;
}

}  // namespace vola::tile
