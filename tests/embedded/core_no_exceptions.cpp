// The core built and used with -fno-exceptions -fno-rtti (docs/EMBEDDED.md).
//   core_no_exceptions SCRATCH_DIR        builds, writes, reads and maps a tree; checks
//                                         every answer against a brute-force set; exit 0
//   core_no_exceptions SCRATCH_DIR error  reads a broken file: the error handler gets the
//                                         message (file and byte offset) and exits 0
// Any other outcome (a wrong answer, abort, handler not called) exits non-zero.
#if defined(__cpp_exceptions) || defined(__EXCEPTIONS) || defined(__GXX_RTTI)
#error "this test must be compiled with -fno-exceptions -fno-rtti"
#endif

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "vola/vola.hpp"

namespace {

int failures = 0;
void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "check failed: %s\n", what);
    ++failures;
  }
}

void handled(const char* message) {
  std::printf("handled: %s\n", message);
  std::fflush(stdout);
  std::_Exit(0);
}

bool same_voxels(const vola::Tree& a, const std::set<std::tuple<unsigned, unsigned, unsigned>>& expected) {
  std::set<std::tuple<unsigned, unsigned, unsigned>> got;
  a.for_each_voxel([&](const vola::Voxel& v) { got.emplace(v.x, v.y, v.z); });
  return got == expected;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: core_no_exceptions SCRATCH_DIR [error]\n");
    return 2;
  }
  const std::string dir = argv[1];
  if (argc > 2 && std::strcmp(argv[2], "error") == 0) {
    const std::string bad = dir + "/broken.vol";
    std::FILE* f = std::fopen(bad.c_str(), "wb");
    if (!f) return 3;
    std::fputs("this is not a VOLA file at all, and too short for a header", f);
    std::fclose(f);
    vola::set_error_handler(&handled);
    vola::read(bad);
    std::fprintf(stderr, "read of a broken file returned\n");
    return 1;
  }

  std::vector<vola::Voxel> voxels;
  std::set<std::tuple<unsigned, unsigned, unsigned>> expected;
  unsigned seed = 12345;
  for (int i = 0; i < 2000; ++i) {
    seed = seed * 1103515245u + 12345u;
    const vola::Voxel v{(seed >> 4) % 64, (seed >> 10) % 64, (seed >> 16) % 64};
    voxels.push_back(v);
    expected.emplace(v.x, v.y, v.z);
  }
  const vola::Tree tree = vola::build_from_voxels(voxels, 3);
  check(tree.voxel_count() == expected.size(), "voxel count");
  check(same_voxels(tree, expected), "iteration");
  bool contains_ok = true;
  for (unsigned x = 0; x < 64; ++x)
    for (unsigned y = 0; y < 64; ++y)
      for (unsigned z = 0; z < 64; ++z) contains_ok &= tree.contains(x, y, z) == (expected.count({x, y, z}) == 1);
  check(contains_ok, "contains");

  const std::string path = dir + "/tree.vol";
  vola::write(tree, path);
  check(same_voxels(vola::read(path), expected), "read back");
  const vola::Tree mapped = vola::open_mapped(path);
  check(mapped.is_mapped() && same_voxels(mapped, expected), "mapped back");
  check(mapped.level_of_detail(2).voxel_count() == tree.node_count(1), "level of detail");
  if (failures) return 1;
  std::printf("core without exceptions or RTTI: %llu voxels built, written, read and mapped\n",
              static_cast<unsigned long long>(tree.voxel_count()));
  return 0;
}
