// Checks of the files a command is given, before any byte is read or written.
#pragma once

#include <string>

namespace vola::io {

// Writers refuse to write over their own input: every output is written whole and then
// renamed onto its name, so an output naming the input replaces it (a filtered translate
// would leave only the subset of the survey).
// Throws InvalidArgument "OUTPUT is the input: ADVICE" when both names reach the same
// file (links and different spellings included); nothing when the output does not exist.
void refuse_output_over_input(const std::string& input, const std::string& output, const std::string& advice);

// Inputs are files: a FIFO would block its reader until someone writes into it (forever,
// most often), a device (/dev/zero) never end. Throws InvalidArgument naming what the
// path is when it exists and is not a regular file (after links); nothing otherwise (a
// missing file is the reader's to report).
void refuse_non_regular_input(const std::string& path);

// An input that cannot be opened for reading (missing, no permission) is an IoError with
// the system's reason ("cannot open: No such file or directory"): called where reading
// begins (convert, read_input, read_point_table, translate_points), not by
// find_input_format, which names a format for any path.
void refuse_unopenable_input(const std::string& path);

}  // namespace vola::io
