// NumPy .npz archives (a zip of .npy members, stored or deflated, as numpy.savez and
// numpy.savez_compressed write them) through libzip.
#pragma once

#include <string>
#include <vector>

#include "vola/io/npy.hpp"

namespace vola::io {

// Member names of the archive, without the ".npy" suffix, in archive order.
// Throws IoError when the file cannot be opened, FormatError when it is not a zip.
std::vector<std::string> npz_array_names(const std::string& path);

// One member (name without ".npy") parsed as .npy. The member is inflated into a
// buffer no larger than what its stated size says and deflate can yield from its
// compressed bytes; a member that inflates past its stated size is an error.
NpyArray read_npz_array(const std::string& path, const std::string& name);

// The member a point file's reader takes (InputOptions::member, else the archive's
// only array, else the one named as point arrays are: points, xyz, positions, pos,
// point_cloud, pc, cloud). Throws FormatError listing the arrays when none or several
// qualify.
std::string npz_points_member(const std::string& path, const std::string& wanted);

}  // namespace vola::io
