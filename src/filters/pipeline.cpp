#include "vola/filters/pipeline.hpp"

#include <cctype>
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <utility>
#include <vector>

#include "vola/error.hpp"
#include "vola/filters/dimensions.hpp"
#include "vola/filters/stages.hpp"

namespace vola::filters {

namespace {

using nlohmann::json;

std::string lower_extension(const std::string& path) {
  const auto dot = path.rfind('.');
  std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

std::string number_text(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

// A JSON value as an error message quotes it: at most 80 characters of its text.
std::string quoted(const json& value) {
  std::string text = value.dump();
  if (text.size() > 80) text = text.substr(0, 77) + "...";
  return text;
}

// A stage's numeric option: a JSON number or a string holding one (PDAL takes both).
double numeric(const json& value, const std::string& where) {
  if (value.is_number()) return value.get<double>();
  if (value.is_string()) {
    const std::string text = value.get<std::string>();
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (!text.empty() && *end == '\0') return v;
  }
  throw InvalidArgument(where + " must be a number, not " + quoted(value));
}

class StageReader {
 public:
  StageReader(const json& stage, std::size_t index) : stage_(stage) {
    prefix_ = "pipeline stage " + std::to_string(index) + ": ";
    if (stage.contains("type") && !stage["type"].is_string())
      fail("\"type\" must be a string, not " + quoted(stage["type"]));
    type_ = stage.value("type", "");
    if (!type_.empty()) prefix_ = "pipeline stage " + std::to_string(index) + " (" + type_ + "): ";
  }
  const std::string& type() const { return type_; }
  [[noreturn]] void fail(const std::string& what) const { throw InvalidArgument(prefix_ + what); }
  bool has(const char* key) const { return stage_.contains(key); }
  // A number of an option's value, its error said with the stage's prefix.
  double number_in(const json& value, const std::string& what) const {
    try {
      return numeric(value, what);
    } catch (const InvalidArgument& e) {
      fail(e.what());
    }
  }
  double number(const char* key) const {
    if (!stage_.contains(key)) fail(std::string("needs \"") + key + "\"");
    try {
      return numeric(stage_.at(key), std::string("\"") + key + "\"");
    } catch (const InvalidArgument& e) {
      fail(e.what());
    }
  }
  std::string text(const char* key) const {
    if (!stage_.contains(key) || !stage_.at(key).is_string()) fail(std::string("needs \"") + key + "\" as a string");
    return stage_.at(key).get<std::string>();
  }
  // Every key must be one of `known` (and type, tag).
  void only(std::initializer_list<const char*> known) const {
    for (const auto& [key, value] : stage_.items()) {
      if (key == "type" || key == "tag") continue;
      bool ok = false;
      std::string list;
      for (const char* k : known) {
        ok = ok || key == k;
        list += std::string(list.empty() ? "" : ", ") + k;
      }
      if (!ok) fail("no option \"" + key + "\"" + (list.empty() ? " (it takes none)" : " (it takes " + list + ")"));
    }
  }
  // The stage string of a filter, checked by parse_stage.
  std::string filter() const {
    std::string spec;
    if (type_ == "filters.smrf") {
      only({"cell", "slope", "window", "threshold", "scalar"});
      spec = "smrf";
      std::string params;
      for (const char* key : {"cell", "slope", "window", "threshold", "scalar"})
        if (has(key)) params += std::string(params.empty() ? "" : ",") + key + "=" + number_text(number(key));
      if (!params.empty()) spec += ":" + params;
    } else if (type_ == "filters.range") {
      only({"limits"});
      const std::string limits = text("limits");
      try {
        spec = "where:" + range_expression(limits);
      } catch (const InvalidArgument& e) {
        fail(e.what());
      }
    } else if (type_ == "filters.expression") {
      only({"expression"});
      spec = "where:" + text("expression");
    } else if (type_ == "filters.hag_nn" || type_ == "filters.hag") {
      only({"count"});
      if (has("count") && number("count") != 1) fail("vola's height above ground uses the nearest ground point (count 1)");
      spec = "hag";
    } else if (type_ == "filters.outlier") {
      only({"method", "mean_k", "multiplier"});
      if (has("method") && text("method") != "statistical") fail("only the \"statistical\" method is implemented");
      spec = "outlier";
      std::string params;
      if (has("mean_k")) params += "k=" + number_text(number("mean_k"));
      if (has("multiplier")) params += std::string(params.empty() ? "" : ",") + "multiplier=" + number_text(number("multiplier"));
      if (!params.empty()) spec += ":" + params;
    } else if (type_ == "filters.crop") {
      only({"bounds", "polygon"});
      if (has("bounds") == has("polygon")) fail("give \"bounds\" or \"polygon\" (one of them)");
      spec = has("bounds") ? crop_bounds(stage_.at("bounds")) : "polygon:" + text("polygon");
    } else if (type_ == "filters.sample") {
      // PDAL takes the radius, or the cell of a voxel that sphere circumscribes.
      only({"radius", "cell"});
      if (has("radius") == has("cell")) fail("give \"radius\" or \"cell\" (one of them)");
      const double radius = has("radius") ? number("radius") : number("cell") * std::sqrt(3.0) / 2.0;
      spec = "poisson:" + number_text(radius);
    } else if (type_ == "filters.voxelcenternearestneighbor") {
      only({"cell"});
      spec = "voxel:" + number_text(has("cell") ? number("cell") : 1.0);  // PDAL's default cell: 1
    } else {
      fail("unknown stage type (vola runs readers.*, filters.smrf, filters.range, filters.expression, filters.hag_nn, "
           "filters.outlier, filters.crop, filters.sample, filters.voxelcenternearestneighbor, writers.las, writers.ply, "
           "writers.text, writers.vola)");
    }
    try {
      parse_stage(spec);
    } catch (const Error& e) {
      fail(e.what());
    }
    return spec;
  }

 private:
  // PDAL's bounds, in its three forms: "([minx, maxx], [miny, maxy])" or with
  // "[minz, maxz]"; a GeoJSON bbox [minx, miny, maxx, maxy] or [minx, miny, minz, maxx,
  // maxy, maxz]; an object {"minx": ..., "miny": ..., "maxx": ..., "maxy": ...} with
  // "minz" and "maxz" or without. As text or as JSON itself.
  std::string crop_bounds(const json& value) const {
    const std::string text = value.is_string() ? value.get<std::string>() : value.dump();
    const char* forms =
        "\"bounds\" must be \"([minx, maxx], [miny, maxy])\" (or with \"[minz, maxz]\"), a GeoJSON bbox "
        "[minx, miny, maxx, maxy] (or [minx, miny, minz, maxx, maxy, maxz]), or {\"minx\": ..., \"miny\": ..., "
        "\"maxx\": ..., \"maxy\": ...} (with \"minz\" and \"maxz\" or without)";
    // min x, min y, max x, max y (and min z, max z)
    std::vector<double> box;
    const json parsed = json::parse(text, nullptr, false);
    if (!parsed.is_discarded() && parsed.is_array()) {
      for (const json& v : parsed) box.push_back(number_in(v, "a bound"));
      if (box.size() == 6)
        box = {box[0], box[1], box[3], box[4], box[2], box[5]};
      else if (box.size() != 4)
        fail(std::string(forms) + ", not " + text);
    } else if (!parsed.is_discarded() && parsed.is_object()) {
      for (const auto& [key, v] : parsed.items())
        if (key != "minx" && key != "miny" && key != "minz" && key != "maxx" && key != "maxy" && key != "maxz")
          fail(std::string(forms) + ": no key \"" + key + "\"");
      for (const char* key : {"minx", "miny", "maxx", "maxy"}) {
        if (!parsed.contains(key)) fail(std::string(forms) + ": \"" + key + "\" is missing");
        box.push_back(number_in(parsed.at(key), std::string("\"") + key + "\""));
      }
      if (parsed.contains("minz") != parsed.contains("maxz"))
        fail(std::string(forms) + ": \"minz\" and \"maxz\" go together");
      if (parsed.contains("minz")) {
        box.push_back(number_in(parsed.at("minz"), "\"minz\""));
        box.push_back(number_in(parsed.at("maxz"), "\"maxz\""));
      }
    } else {
      box = classic_bounds(text, forms);
    }
    if (box.size() == 4)
      return "crop:" + number_text(box[0]) + "," + number_text(box[1]) + "," + number_text(box[2]) + "," +
             number_text(box[3]);
    return "crop:" + number_text(box[0]) + "," + number_text(box[1]) + "," + number_text(box[4]) + "," +
           number_text(box[2]) + "," + number_text(box[3]) + "," + number_text(box[5]);
  }
  // "([minx, maxx], [miny, maxy])" or with "[minz, maxz]": minx, miny, maxx, maxy (minz, maxz).
  std::vector<double> classic_bounds(const std::string& text, const char* forms) const {
    std::vector<std::pair<double, double>> pairs;
    std::size_t i = 0;
    const auto skip = [&] {
      while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    };
    const auto expect = [&](char c) {
      skip();
      if (i >= text.size() || text[i] != c) fail(std::string(forms) + ", not " + text);
      ++i;
    };
    const auto number_until = [&](char end) {
      const std::size_t stop = text.find(end, i);
      if (stop == std::string::npos) fail(std::string(forms) + ", not " + text);
      std::string digits = text.substr(i, stop - i);
      digits.erase(0, digits.find_first_not_of(" \t"));
      digits.erase(digits.find_last_not_of(" \t") + 1);
      i = stop + 1;
      return number_in(json(digits), "a bound");
    };
    expect('(');
    do {
      expect('[');
      const double low = number_until(',');
      const double high = number_until(']');
      pairs.emplace_back(low, high);
      skip();
    } while (i < text.size() && text[i] == ',' && ++i);
    expect(')');
    skip();
    if (i != text.size() || (pairs.size() != 2 && pairs.size() != 3)) fail(std::string(forms) + ", not " + text);
    std::vector<double> box{pairs[0].first, pairs[1].first, pairs[0].second, pairs[1].second};
    if (pairs.size() == 3) box.insert(box.end(), {pairs[2].first, pairs[2].second});
    return box;
  }
  const json& stage_;
  std::string type_, prefix_;
};

// A file named without a type is what PDAL makes of it: the input when first, the output
// when last, and another input anywhere else (PDAL merges it with the first). vola
// pipelines read one input, so a name in between is refused: taken as a writer, it
// would overwrite a file PDAL reads.
void refuse_untyped_middle(const std::string& file, std::size_t index, std::size_t stages) {
  if (index == 0 || index + 1 == stages) return;
  throw InvalidArgument("pipeline stage " + std::to_string(index) + ": " + file +
                        ": a file named without a type between the first and the last stage is another input to "
                        "PDAL (merged with the first), and vola pipelines read one; merge the inputs first, or give "
                        "an output its type ({\"type\": \"writers.las\", \"filename\": \"" +
                        file + "\"})");
}

void add_untyped_file(const std::string& file, std::size_t index, std::size_t stages, Pipeline& pipeline) {
  refuse_untyped_middle(file, index, stages);
  if (index == 0)
    pipeline.input = file;
  else
    pipeline.writers.push_back({file, {}});
}

// The reader PDAL would infer from a name's extension (the label of its messages).
std::string reader_type_of(const std::string& filename) {
  const std::string extension = lower_extension(filename);
  if (extension == ".las" || extension == ".laz") return "readers.las";
  if (extension == ".xyz" || extension == ".txt" || extension == ".csv") return "readers.text";
  return extension.size() > 1 ? "readers." + extension.substr(1) : "readers.las";
}

// The writer PDAL would infer from a name's extension; empty when vola writes no such file.
std::string writer_type_of(const std::string& filename) {
  const std::string extension = lower_extension(filename);
  return extension == ".vol"                                                 ? "writers.vola"
         : extension == ".las" || extension == ".laz"                        ? "writers.las"
         : extension == ".ply"                                               ? "writers.ply"
         : extension == ".xyz" || extension == ".txt" || extension == ".csv" ? "writers.text"
                                                                             : "";
}

// One object stage into `pipeline`: a reader, a writer or a filter.
void read_stage(const json& element, std::size_t index, std::size_t stages, Pipeline& pipeline) {
  const StageReader stage(element, index);
  const std::string& type = stage.type();
  if (type.empty() && element.contains("filename")) {
    // PDAL infers the kind from the position: checked as that stage, options and all
    // (options on an untyped stage were dropped without a word).
    const std::string file = stage.text("filename");
    refuse_untyped_middle(file, index, stages);
    json typed = element;
    typed["type"] = index == 0 ? reader_type_of(file) : writer_type_of(file);
    if (index != 0 && typed["type"] == "")
      stage.fail(file + ": vola writes by the name's extension: .vol, .las, .laz, .ply, .xyz, .txt or .csv");
    read_stage(typed, index, stages, pipeline);
    return;
  }
  if (type.rfind("readers.", 0) == 0) {
    if (index != 0) stage.fail("a reader must come first (vola pipelines read one input)");
    stage.only({"filename"});
    pipeline.input = stage.text("filename");
  } else if (type.rfind("writers.", 0) == 0) {
    PipelineWriter writer;
    writer.filename = stage.text("filename");
    // The output's name decides what is written: a type that says otherwise is refused
    // (writers.vola named o.las wrote LAS and dropped voxel_size without a word).
    const std::string extension = lower_extension(writer.filename);
    const std::string wants = writer_type_of(writer.filename);
    if (wants.empty())
      stage.fail(writer.filename + ": vola writes by the name's extension: .vol, .las, .laz, .ply, .xyz, .txt or .csv");
    if (type != wants)
      stage.fail(type + " cannot write " + writer.filename + ": vola writes by the name's extension, and " + extension +
                 " is " + wants);
    if (type == "writers.vola" || writer.voxels()) {
      stage.only({"filename", "voxel_size", "depth", "compress", "compress_max", "dense", "attributes"});
      for (const auto& [key, value] : element.items())
        if (key != "type" && key != "tag" && key != "filename") writer.options[key] = value.dump();
    } else if (type == "writers.las") {
      // PDAL's two options most pipelines carry, where vola does what they ask anyway: the
      // header and (E)VLRs of a LAS input are kept ("forward": "all"), and the extension
      // says whether the points are compressed. Options vola would ignore are refused.
      stage.only({"filename", "forward", "compression"});
      if (element.contains("forward") && !(element.at("forward").is_string() && element.at("forward") == "all"))
        stage.fail("\"forward\" takes \"all\" only (vola keeps a LAS input's header and VLRs whole)");
      if (element.contains("compression")) {
        const json& c = element.at("compression");
        const bool compressed = c.is_boolean() ? c.get<bool>()
                                : c.is_string() && (c == "laszip" || c == "lazperf" || c == "true");
        const bool plain = c.is_boolean() ? !c.get<bool>() : c.is_string() && (c == "none" || c == "false");
        const bool laz = lower_extension(writer.filename) == ".laz";
        if (!(compressed || plain)) stage.fail("\"compression\" takes \"laszip\", \"lazperf\", \"none\", true or false");
        if (compressed != laz)
          stage.fail("\"compression\" disagrees with the name " + writer.filename +
                     " (vola compresses exactly the .laz outputs)");
      }
    } else if (type == "writers.ply" || type == "writers.text") {
      stage.only({"filename"});
    } else {
      stage.fail("unknown writer (writers.las for .las/.laz, writers.ply, writers.text, writers.vola for .vol)");
    }
    pipeline.writers.push_back(std::move(writer));
  } else {
    if (!pipeline.writers.empty()) stage.fail("a filter after a writer (vola runs the filters, then every writer)");
    pipeline.stages.push_back(stage.filter());
  }
}

}  // namespace

bool PipelineWriter::voxels() const { return lower_extension(filename) == ".vol"; }

std::string range_expression(const std::string& limits) {
  // Per dimension (in order of first appearance), its ranges joined by ||.
  std::vector<std::pair<std::string, std::vector<std::string>>> groups;
  std::size_t i = 0;
  const auto fail = [&](const std::string& what) {
    throw InvalidArgument("limits \"" + limits + "\": at character " + std::to_string(i + 1) + ": " + what);
  };
  while (i < limits.size()) {
    while (i < limits.size() && (limits[i] == ',' || std::isspace(static_cast<unsigned char>(limits[i])))) ++i;
    if (i >= limits.size()) break;
    std::string name;
    while (i < limits.size() && (std::isalnum(static_cast<unsigned char>(limits[i])) || limits[i] == '_')) name += limits[i++];
    if (name.empty()) fail("expected a dimension name");
    const bool negate = i < limits.size() && limits[i] == '!';
    if (negate) ++i;
    if (i >= limits.size() || (limits[i] != '[' && limits[i] != '(')) fail("expected [ or ( after " + name);
    const bool open_low = limits[i++] == '(';
    const auto colon = limits.find(':', i);
    if (colon == std::string::npos) fail("expected MIN:MAX");
    const auto close = limits.find_first_of("])", colon);
    if (close == std::string::npos) fail("expected ] or )");
    const std::string low = limits.substr(i, colon - i), high = limits.substr(colon + 1, close - colon - 1);
    const bool open_high = limits[close] == ')';
    std::string range;
    const auto bound = [&](std::string text, const char* closed_op, const char* open_op, bool open) {
      // Spaces around a limit are allowed, as PDAL reads it: "Z[ 420 : 430 ]".
      text.erase(0, text.find_first_not_of(" \t"));
      text.erase(text.find_last_not_of(" \t") + 1);
      if (text.empty()) return std::optional<double>();
      const double v = numeric(json(text), "a limit");
      range += std::string(range.empty() ? "" : " && ") + name + " " + (open ? open_op : closed_op) + " " + number_text(v);
      return std::optional<double>(v);
    };
    const std::optional<double> from = bound(low, ">=", ">", open_low), to = bound(high, "<=", "<", open_high);
    // An empty range is a mistake, not a request for no points (the CLI's --crop refuses one too).
    if (from && to && (*from > *to || (*from == *to && (open_low || open_high))))
      fail(name + "'s range " + limits.substr(i - 1, close - i + 2) + " holds no value (a minimum of " +
           number_text(*from) + ", a maximum of " + number_text(*to) + ")");
    if (range.empty()) range = name + " == " + name;  // [:] : any value (NaN aside)
    range = "(" + range + ")";
    if (negate) range = "!" + range;
    i = close + 1;
    auto group = std::find_if(groups.begin(), groups.end(),
                              [&](const auto& g) { return dimension_key(g.first) == dimension_key(name); });
    if (group == groups.end()) groups.push_back({name, {range}});
    else group->second.push_back(range);
  }
  if (groups.empty()) fail("no range");
  std::string expression;
  for (const auto& [name, ranges] : groups) {
    std::string joined;
    for (const auto& r : ranges) joined += (joined.empty() ? "" : " || ") + r;
    expression += std::string(expression.empty() ? "" : " && ") + (ranges.size() > 1 ? "(" + joined + ")" : joined);
  }
  return expression;
}

// Deeper than any pipeline needs (a stage's option is a number, a string or a list of
// bounds): the values are written back out as text, which recurses once per level, and a
// value nested 100,000 deep took the process down with it.
constexpr int kMaxPipelineNesting = 64;

Pipeline parse_pipeline(const std::string& text, const std::string& name) {
  json document;
  try {
    document = json::parse(text, [&](int depth, json::parse_event_t, json&) {
      if (depth > kMaxPipelineNesting)
        throw InvalidArgument(name + ": JSON nested deeper than " + std::to_string(kMaxPipelineNesting) +
                              " levels; a pipeline is an array of stages whose options are numbers, strings and "
                              "short lists");
      return true;
    });
  } catch (const json::exception& e) {
    throw InvalidArgument(name + ": not JSON: " + e.what());
  }
  if (document.is_object() && document.contains("pipeline")) document = document["pipeline"];
  if (!document.is_array() || document.empty())
    throw InvalidArgument(name + ": a pipeline is a JSON array of stages (or {\"pipeline\": [...]})");
  Pipeline pipeline;
  for (std::size_t index = 0; index < document.size(); ++index) {
    const json& element = document[index];
    const std::string prefix = "pipeline stage " + std::to_string(index) + ": ";
    if (element.is_string()) {
      add_untyped_file(element.get<std::string>(), index, document.size(), pipeline);
      continue;
    }
    if (!element.is_object()) throw InvalidArgument(prefix + "a stage is a file name or an object with \"type\"");
    try {
      read_stage(element, index, document.size(), pipeline);
    } catch (const json::exception& e) {  // a member of an unexpected JSON type
      throw InvalidArgument(prefix + e.what());
    }
  }
  if (pipeline.input.empty()) throw InvalidArgument(name + ": the pipeline has no reader (a file name first)");
  if (pipeline.writers.empty()) throw InvalidArgument(name + ": the pipeline has no writer (a file name last)");
  return pipeline;
}

}  // namespace vola::filters
