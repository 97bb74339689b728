// Outputs that would land on an input: a PNG, CSV, WAV or map written over the scene,
// recording or scan list it is made from, with exit 0 (convert, export and translate
// refused it; render, plan, sonify and map did not).
#pragma once

#include <string>
#include <vector>

namespace vola::cli {

// Throws InvalidArgument naming the output when it is one of `inputs` (the same file by
// any path: ./, a symlink, a hard link). Empty names are skipped.
void refuse_outputs_over_inputs(const std::vector<std::string>& inputs, const std::vector<std::string>& outputs,
                                const std::string& command);

}  // namespace vola::cli
