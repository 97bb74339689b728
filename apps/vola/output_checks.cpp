#include "output_checks.hpp"

#include "vola/io/file_checks.hpp"

namespace vola::cli {

void refuse_outputs_over_inputs(const std::vector<std::string>& inputs, const std::vector<std::string>& outputs,
                                const std::string& command) {
  for (const std::string& output : outputs)
    for (const std::string& input : inputs)
      if (!output.empty() && !input.empty())
        io::refuse_output_over_input(input, output, command + " writes new files; give this output another name");
}

}  // namespace vola::cli
