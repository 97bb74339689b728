#include "option_flags.hpp"

#include <map>

namespace vola::cli {

std::string flag_of(const std::string& option) {
  // Members whose flag is not simply --member-name.
  static const std::map<std::string, std::string> renamed = {
      {"quantization", "--quantize"},     {"epsg", "--assign-crs"},          {"text_attributes", "--attribute"},
      {"attributes", "--no-attributes"},  {"memory_budget", "--memory"}, {"bin_width_db", "--bin-width"},
      {"floor_db", "--floor"},            {"architecture", "--arch"},  {"output_dir", "-o"},
      {"filters", "--filter"},            {"inputs", "inputs"}};
  if (const auto it = renamed.find(option); it != renamed.end()) return it->second;
  std::string flag = "--" + option;
  for (char& c : flag)
    if (c == '_') c = '-';
  return flag;
}

std::string with_flags(std::string text) {
  for (std::size_t open = text.find('`'); open != std::string::npos; open = text.find('`', open)) {
    const std::size_t close = text.find('`', open + 1);
    if (close == std::string::npos) break;
    const std::string flag = flag_of(text.substr(open + 1, close - open - 1));
    text.replace(open, close - open + 1, flag);
    open += flag.size();
  }
  return text;
}

std::string in_flags(const OptionError& error) {
  if (error.option().empty()) return with_flags(error.cause());
  return flag_of(error.option()) + ": " + with_flags(error.cause());
}

}  // namespace vola::cli
