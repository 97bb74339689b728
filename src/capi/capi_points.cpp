// vola_export_las and vola_translate: a tree's voxels as LAS/LAZ points, and point files
// to point files (include/vola/io/export.hpp, include/vola/io/translate.hpp), when the
// library is built with its readers and writers.
#include "capi_guard.hpp"
#include "vola/vola.h"

#ifdef VOLA_C_HAS_CONVERT
#include <string>

#include "vola/io/export.hpp"
#include "vola/io/input.hpp"
#include "vola/io/translate.hpp"
#endif

extern "C" {

vola_status vola_export_las(const vola_tree* tree, const char* path) {
  return vola::capi::guarded([&] {
    vola::capi::require(tree != nullptr && path != nullptr, "vola_export_las: tree and path must not be NULL");
#ifdef VOLA_C_HAS_CONVERT
    // The CLI picks the format by the extension; here LAS is asked for, so another
    // extension (out.txt, out.ply) would hold LAS bytes under a misleading name.
    const std::string extension = vola::io::lower_extension(path);
    if (extension != ".las" && extension != ".laz")
      throw vola::InvalidArgument(std::string("vola_export_las: ") + path + " does not end in .las or .laz");
    vola::io::write_las(vola::capi::tree_of(tree), path);
#else
    throw vola::InvalidArgument("vola_export_las: this library was built without writers (VOLA_BUILD_MODULES=OFF)");
#endif
  });
}

vola_status vola_translate(const char* input, const char* output) {
  return vola::capi::guarded([&] {
    vola::capi::set_last_warnings({});
    vola::capi::require(input != nullptr && output != nullptr, "vola_translate: input and output must not be NULL");
#ifdef VOLA_C_HAS_CONVERT
    vola::capi::set_last_warnings(vola::io::translate_points(input, output));
#else
    throw vola::InvalidArgument("vola_translate: this library was built without readers (VOLA_BUILD_MODULES=OFF)");
#endif
  });
}

}  // extern "C"
