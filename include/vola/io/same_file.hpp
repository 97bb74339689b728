// Writers refuse to write over their own input: every output is written whole and then
// renamed onto its name, so an output naming the input replaces it (a filtered translate
// would leave only the subset of the survey).
#pragma once

#include <string>

namespace vola::io {

// Throws InvalidArgument "OUTPUT is the input: ADVICE" when both names reach the same
// file (links and different spellings included); nothing when the output does not exist.
void refuse_output_over_input(const std::string& input, const std::string& output, const std::string& advice);

}  // namespace vola::io
