/* The C API from C: every entry point on a random cloud against brute-force answers,
 * files written and read back (in memory and mapped), and the error paths (status code
 * and message). Usage: test_capi SCRATCH_DIR. Prints one line per failed check; exit 1
 * on any failure. */
#define _POSIX_C_SOURCE 200809L /* truncate() */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "vola/vola.h"

static int failures = 0;

#define CHECK(cond)                                                   \
  do {                                                                \
    if (!(cond)) {                                                    \
      fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
      ++failures;                                                     \
    }                                                                 \
  } while (0)

#define CHECK_OK(call)                                                                    \
  do {                                                                                    \
    vola_status s_ = (call);                                                              \
    if (s_ != VOLA_OK) {                                                                  \
      fprintf(stderr, "%s:%d: %s -> %s: %s\n", __FILE__, __LINE__, #call, vola_status_string(s_), vola_last_error()); \
      ++failures;                                                                         \
    }                                                                                     \
  } while (0)

enum { kDepth = 3, kSide = 64, kVoxels = 700 };

/* The occupied voxels as a dense bitmap: the slow obvious reference. */
static unsigned char occupied[kSide][kSide][kSide];

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static uint32_t next_random(uint32_t bound) {
  rng_state ^= rng_state << 13;
  rng_state ^= rng_state >> 7;
  rng_state ^= rng_state << 17;
  return (uint32_t)(rng_state % bound);
}

/* VOLA key order: one 6-bit digit per level, level 0 most significant. */
static uint64_t key_of(uint32_t x, uint32_t y, uint32_t z) {
  uint64_t key = 0;
  for (int level = 0; level < kDepth; ++level) {
    const int shift = 2 * (kDepth - 1 - level);
    key = (key << 6) | (((x >> shift) & 3u) + 4u * ((y >> shift) & 3u) + 16u * ((z >> shift) & 3u));
  }
  return key;
}

struct visit_state {
  uint64_t count;
  uint64_t last_key;
  int in_order;
  int all_occupied;
  uint64_t stop_after; /* 0 = never */
};

static int visit(uint32_t x, uint32_t y, uint32_t z, void *user) {
  struct visit_state *s = (struct visit_state *)user;
  const uint64_t key = key_of(x, y, z);
  if (s->count > 0 && key <= s->last_key) s->in_order = 0;
  if (x >= kSide || y >= kSide || z >= kSide || !occupied[x][y][z]) s->all_occupied = 0;
  s->last_key = key;
  ++s->count;
  return s->stop_after != 0 && s->count == s->stop_after;
}

static uint64_t count_occupied(void) {
  uint64_t n = 0;
  for (int x = 0; x < kSide; ++x)
    for (int y = 0; y < kSide; ++y)
      for (int z = 0; z < kSide; ++z) n += occupied[x][y][z];
  return n;
}

/* Same voxels, same order, same info: what a file round trip must keep. */
static void check_same_tree(const vola_tree *a, const vola_tree *b) {
  vola_info ia, ib;
  CHECK_OK(vola_get_info(a, &ia));
  CHECK_OK(vola_get_info(b, &ib));
  CHECK(ia.depth == ib.depth && ia.voxel_count == ib.voxel_count);
  uint32_t *va = malloc(3 * sizeof(uint32_t) * (size_t)ia.voxel_count);
  uint32_t *vb = malloc(3 * sizeof(uint32_t) * (size_t)ib.voxel_count);
  size_t na = 0, nb = 0;
  CHECK_OK(vola_copy_voxels(a, 0, va, (size_t)ia.voxel_count, &na));
  CHECK_OK(vola_copy_voxels(b, 0, vb, (size_t)ib.voxel_count, &nb));
  CHECK(na == ia.voxel_count && nb == ib.voxel_count);
  CHECK(na == nb && memcmp(va, vb, 3 * sizeof(uint32_t) * na) == 0);
  free(va);
  free(vb);
}

static void test_build_query_iterate(const char *scratch) {
  uint32_t *xyz = malloc(3 * sizeof(uint32_t) * kVoxels);
  for (int i = 0; i < kVoxels; ++i) {
    xyz[3 * i] = next_random(kSide);
    xyz[3 * i + 1] = next_random(kSide);
    xyz[3 * i + 2] = next_random(kSide);
    occupied[xyz[3 * i]][xyz[3 * i + 1]][xyz[3 * i + 2]] = 1;
  }
  vola_tree *tree = NULL;
  CHECK_OK(vola_build_from_voxels(xyz, kVoxels, kDepth, &tree));
  free(xyz);
  if (!tree) return;

  vola_info info;
  CHECK_OK(vola_get_info(tree, &info));
  CHECK(info.depth == kDepth && info.side == kSide && info.voxel_count == count_occupied() && !info.mapped);

  /* contains and contains_many against the bitmap, on every cell; rank counts in key order. */
  uint32_t *all = malloc(3 * sizeof(uint32_t) * kSide * kSide * kSide);
  uint8_t *hits = malloc((size_t)kSide * kSide * kSide);
  size_t n = 0;
  for (uint32_t x = 0; x < kSide; ++x)
    for (uint32_t y = 0; y < kSide; ++y)
      for (uint32_t z = 0; z < kSide; ++z, ++n) {
        all[3 * n] = x;
        all[3 * n + 1] = y;
        all[3 * n + 2] = z;
        int hit = -1;
        CHECK_OK(vola_contains(tree, x, y, z, &hit));
        CHECK(hit == occupied[x][y][z]);
      }
  CHECK_OK(vola_contains_many(tree, all, n, hits));
  int many_agree = 1;
  for (size_t i = 0; i < n; ++i) many_agree &= hits[i] == occupied[all[3 * i]][all[3 * i + 1]][all[3 * i + 2]];
  CHECK(many_agree);
  free(all);
  free(hits);
  int off_grid = -1;
  CHECK_OK(vola_contains(tree, kSide, 0, 0, &off_grid));
  CHECK(off_grid == 0);

  /* Iteration: every voxel once, in key order; ranks follow the same order. */
  struct visit_state s = {0, 0, 1, 1, 0};
  uint64_t visited = 0;
  CHECK_OK(vola_for_each_voxel(tree, visit, &s, &visited));
  CHECK(s.count == info.voxel_count && visited == s.count && s.in_order && s.all_occupied);
  struct visit_state stop = {0, 0, 1, 1, 5};
  CHECK_OK(vola_for_each_voxel(tree, visit, &stop, &visited));
  CHECK(stop.count == 5 && visited == 5);

  uint32_t page[3 * 64];
  size_t written = 0;
  uint64_t rank_sum_ok = 1;
  for (uint64_t first = 0; first < info.voxel_count; first += written) {
    CHECK_OK(vola_copy_voxels(tree, first, page, 64, &written));
    if (written == 0) break;
    for (size_t i = 0; i < written; ++i) {
      uint64_t rank = 0;
      CHECK_OK(vola_rank(tree, page[3 * i], page[3 * i + 1], page[3 * i + 2], &rank));
      rank_sum_ok &= rank == first + i;
    }
  }
  CHECK(rank_sum_ok);
  CHECK_OK(vola_copy_voxels(tree, info.voxel_count, page, 64, &written));
  CHECK(written == 0);

  /* Level of detail: a coarse cell is occupied iff any of its 4^3 voxels is. */
  vola_tree *coarse = NULL;
  CHECK_OK(vola_level_of_detail(tree, kDepth - 1, &coarse));
  if (coarse) {
    int lod_ok = 1;
    for (uint32_t x = 0; x < kSide / 4; ++x)
      for (uint32_t y = 0; y < kSide / 4; ++y)
        for (uint32_t z = 0; z < kSide / 4; ++z) {
          int any = 0;
          for (int i = 0; i < 64; ++i) any |= occupied[4 * x + (i & 3)][4 * y + ((i >> 2) & 3)][4 * z + (i >> 4)];
          int hit = -1;
          CHECK_OK(vola_contains(coarse, x, y, z, &hit));
          lod_ok &= hit == any;
        }
    CHECK(lod_ok);
  }

  /* Files: sparse, dense, compressed and compressed with mixed occupancy models, read and
     mapped, all give the same voxels. */
  char path[4096];
  const int flags[4] = {VOLA_WRITE_SPARSE, VOLA_WRITE_DENSE, VOLA_WRITE_COMPRESS, VOLA_WRITE_COMPRESS_MAX};
  for (int f = 0; f < 4; ++f) {
    snprintf(path, sizeof path, "%s/capi_%d.vol", scratch, f);
    CHECK_OK(vola_write(tree, path, flags[f]));
    for (int mode = 0; mode < 2; ++mode) {
      vola_tree *back = NULL;
      CHECK_OK(vola_open(path, mode ? VOLA_OPEN_MAPPED : VOLA_OPEN_READ, &back));
      if (!back) continue;
      vola_info bi;
      CHECK_OK(vola_get_info(back, &bi));
      CHECK(bi.mapped == (mode == 1 && flags[f] == VOLA_WRITE_SPARSE));
      check_same_tree(tree, back);
      vola_tree_free(back);
    }
  }
  vola_tree_free(coarse);
  vola_tree_free(tree);
}

static void test_points_and_attributes(void) {
  /* Grid mode: voxel size 1 from origin 0 on the points' corner. */
  const double xyz[] = {0.5, 0.5, 0.5, 3.5, 0.5, 0.5, 3.9, 0.1, 0.2, 1.0 / 0.0, 0.0, 0.0};
  vola_build_options options = {VOLA_QUANTIZE_GRID, 0, 1.0, 0};
  vola_tree *tree = NULL;
  uint64_t dropped = 99;
  CHECK_OK(vola_build_from_points(xyz, 4, &options, &tree, &dropped));
  if (!tree) return;
  vola_info info;
  CHECK_OK(vola_get_info(tree, &info));
  CHECK(info.voxel_count == 2 && dropped == 1 && info.quantization == VOLA_QUANTIZE_GRID && info.voxel_size == 1.0);
  CHECK(info.epsg == 2000 && info.attribute_count == 0);
  int hit = 0;
  CHECK_OK(vola_contains(tree, 0, 0, 0, &hit));
  CHECK(hit == 1);
  CHECK_OK(vola_contains(tree, 3, 0, 0, &hit));
  CHECK(hit == 1);
  const char *name = NULL;
  CHECK(vola_attribute_name(tree, 0, &name) == VOLA_ERROR_INVALID_ARGUMENT && name == NULL);
  double value = 0;
  CHECK(vola_attribute_value(tree, "intensity", 0, &value) == VOLA_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(vola_last_error(), "intensity") != NULL);
  vola_tree_free(tree);

  vola_build_options toolkit = {VOLA_QUANTIZE_TOOLKIT, 2, 0.0, 32610};
  CHECK_OK(vola_build_from_points(xyz, 3, &toolkit, &tree, NULL));
  if (tree) {
    CHECK_OK(vola_get_info(tree, &info));
    CHECK(info.depth == 2 && info.epsg == 32610 && info.quantization == VOLA_QUANTIZE_TOOLKIT);
    vola_tree_free(tree);
  }
}

/* A real file with attribute columns (a converted LAS survey), when the test has one. */
static void test_shared_file(const char *path) {
  vola_tree *read = NULL, *mapped = NULL;
  CHECK_OK(vola_open(path, VOLA_OPEN_READ, &read));
  CHECK_OK(vola_open(path, VOLA_OPEN_MAPPED, &mapped));
  if (!read || !mapped) return;
  check_same_tree(read, mapped);
  vola_info info;
  CHECK_OK(vola_get_info(mapped, &info));
  CHECK(info.attribute_count > 0);
  const char *name = NULL;
  CHECK_OK(vola_attribute_name(mapped, 0, &name));
  double value = -1;
  if (name) CHECK_OK(vola_attribute_value(mapped, name, info.voxel_count - 1, &value));
  if (name) CHECK(vola_attribute_value(mapped, name, info.voxel_count, &value) == VOLA_ERROR_INVALID_ARGUMENT);
  vola_tree_free(read);
  vola_tree_free(mapped);
}

/* The callback of the cut-midway test: truncates the file at the tenth voxel. */
static const char *cut_path = NULL;
static int cut_calls = 0;
static int cut_at_tenth(uint32_t x, uint32_t y, uint32_t z, void *user) {
  (void)x, (void)y, (void)z, (void)user;
  if (++cut_calls == 10) CHECK(truncate(cut_path, 0) == 0);
  return 0;
}

/* A mapped file cut by another process (cp over it, a truncation) leaves zero pages: calls
 * on its tree must fail, not answer from the zeros with VOLA_OK. */
static void test_cut_while_mapped(const char *scratch) {
  enum { kCount = 20000 };
  uint32_t *xyz = malloc(3 * sizeof(uint32_t) * kCount);
  for (int i = 0; i < 3 * kCount; ++i) xyz[i] = next_random(1024);
  vola_tree *built = NULL, *mapped = NULL;
  CHECK_OK(vola_build_from_voxels(xyz, kCount, 5, &built));
  char path[4096];
  snprintf(path, sizeof path, "%s/cut_while_mapped.vol", scratch);
  CHECK_OK(vola_write(built, path, 0));
  CHECK_OK(vola_open(path, VOLA_OPEN_MAPPED, &mapped));
  int hit = -1;
  CHECK_OK(vola_contains(mapped, xyz[0], xyz[1], xyz[2], &hit));
  CHECK(hit == 1);
  CHECK(truncate(path, 0) == 0);
  CHECK(vola_contains(mapped, xyz[0], xyz[1], xyz[2], &hit) == VOLA_ERROR_IO);
  CHECK(strstr(vola_last_error(), "cut_while_mapped.vol") != NULL && strstr(vola_last_error(), "was cut") != NULL);
  vola_info info;
  CHECK(vola_get_info(mapped, &info) == VOLA_ERROR_IO);
  snprintf(path, sizeof path, "%s/from_cut.vol", scratch);
  CHECK(vola_write(mapped, path, 0) == VOLA_ERROR_IO);
  vola_tree_free(mapped);

  /* Cut during a call: an I/O error (not the format error its zero pages would make), and
   * the out-parameters untouched (visited was set to the voxels seen before the cut). */
  snprintf(path, sizeof path, "%s/cut_midway.vol", scratch);
  CHECK_OK(vola_write(built, path, 0));
  CHECK_OK(vola_open(path, VOLA_OPEN_MAPPED, &mapped));
  cut_path = path;
  cut_calls = 0;
  uint64_t visited = 12345;
  CHECK(vola_for_each_voxel(mapped, cut_at_tenth, NULL, &visited) == VOLA_ERROR_IO);
  CHECK(visited == 12345 && cut_calls == 10);
  vola_tree *coarse = NULL;
  CHECK(vola_level_of_detail(mapped, 3, &coarse) == VOLA_ERROR_IO && coarse == NULL);
  CHECK(strstr(vola_last_error(), "cut_midway.vol") != NULL && strstr(vola_last_error(), "was cut") != NULL);
  vola_tree_free(mapped);
  vola_tree_free(built);
  free(xyz);
}

static void test_errors(const char *scratch) {
  vola_tree *tree = NULL;
  char path[4096];
  snprintf(path, sizeof path, "%s/does_not_exist.vol", scratch);
  CHECK(vola_open(path, VOLA_OPEN_READ, &tree) == VOLA_ERROR_IO && tree == NULL);
  CHECK(strstr(vola_last_error(), "does_not_exist.vol") != NULL);

  /* A header cut short: a format error naming the file and a byte offset. */
  snprintf(path, sizeof path, "%s/truncated.vol", scratch);
  FILE *f = fopen(path, "wb");
  CHECK(f != NULL);
  if (f) {
    const char junk[40] = "VOLA? not really";
    fwrite(junk, 1, sizeof junk, f);
    fclose(f);
  }
  for (int mode = 0; mode < 2; ++mode) {
    CHECK(vola_open(path, mode ? VOLA_OPEN_MAPPED : VOLA_OPEN_READ, &tree) == VOLA_ERROR_FORMAT && tree == NULL);
    CHECK(strstr(vola_last_error(), "truncated.vol") != NULL && strstr(vola_last_error(), "byte") != NULL);
  }

  CHECK(vola_open(NULL, VOLA_OPEN_READ, &tree) == VOLA_ERROR_INVALID_ARGUMENT);
  CHECK(vola_open(path, (vola_open_mode)7, &tree) == VOLA_ERROR_INVALID_ARGUMENT);
  const uint32_t voxel[3] = {64, 0, 0};
  CHECK(vola_build_from_voxels(voxel, 1, 3, &tree) == VOLA_ERROR_INVALID_ARGUMENT && tree == NULL);
  CHECK(vola_build_from_voxels(voxel, 1, 11, &tree) == VOLA_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(vola_last_error(), "depth 11") != NULL);
  const double point[3] = {0, 0, 0};
  vola_build_options no_depth = {VOLA_QUANTIZE_TOOLKIT, 0, 0.0, 0};
  CHECK(vola_build_from_points(point, 1, &no_depth, &tree, NULL) == VOLA_ERROR_INVALID_ARGUMENT);
  vola_build_options grid_nothing = {VOLA_QUANTIZE_GRID, 0, 0.0, 0};
  CHECK(vola_build_from_points(point, 1, &grid_nothing, &tree, NULL) == VOLA_ERROR_INVALID_ARGUMENT);
  CHECK(vola_build_from_points(point, 1, NULL, &tree, NULL) == VOLA_ERROR_INVALID_ARGUMENT);

  int hit = 0;
  CHECK(vola_contains(NULL, 0, 0, 0, &hit) == VOLA_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(vola_last_error(), "NULL") != NULL);
  const uint32_t one[3] = {1, 2, 3};
  CHECK_OK(vola_build_from_voxels(one, 1, 2, &tree));
  if (!tree) return;
  uint64_t rank = 0;
  CHECK(vola_rank(tree, 0, 0, 0, &rank) == VOLA_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(vola_last_error(), "not occupied") != NULL);
  CHECK(vola_for_each_voxel(tree, NULL, NULL, NULL) == VOLA_ERROR_INVALID_ARGUMENT);
  vola_tree *lod = NULL;
  CHECK(vola_level_of_detail(tree, 3, &lod) == VOLA_ERROR_INVALID_ARGUMENT && lod == NULL);
  CHECK(vola_level_of_detail(tree, 0, &lod) == VOLA_ERROR_INVALID_ARGUMENT);
  CHECK(vola_write(tree, path, VOLA_WRITE_DENSE | VOLA_WRITE_COMPRESS) == VOLA_ERROR_INVALID_ARGUMENT);
  CHECK(vola_write(tree, path, VOLA_WRITE_DENSE | VOLA_WRITE_COMPRESS_MAX) == VOLA_ERROR_INVALID_ARGUMENT);
  CHECK(vola_write(tree, path, 64) == VOLA_ERROR_INVALID_ARGUMENT);
  snprintf(path, sizeof path, "%s/no_such_dir/out.vol", scratch);
  CHECK(vola_write(tree, path, VOLA_WRITE_SPARSE) == VOLA_ERROR_IO);
  CHECK(strstr(vola_last_error(), "no_such_dir") != NULL);
  CHECK(vola_write(tree, "", VOLA_WRITE_SPARSE) == VOLA_ERROR_IO);
  CHECK(strstr(vola_last_error(), "name is empty") != NULL);  /* the message was "" */
  snprintf(path, sizeof path, "%s/points.txt", scratch);
  CHECK(vola_export_las(tree, path) == VOLA_ERROR_INVALID_ARGUMENT);  /* LAS bytes under a .txt name */
  vola_tree *none = NULL;
  CHECK(vola_build_from_voxels(one, SIZE_MAX / 3, 2, &none) == VOLA_ERROR_INVALID_ARGUMENT && none == NULL);
  vola_convert_options options;
  vola_convert_options_init(&options);
  options.level = -5;
  CHECK(vola_convert(path, &options, &none, NULL) == VOLA_ERROR_INVALID_ARGUMENT);
  vola_convert_options_init(&options);
  options.target_crs = "";
  CHECK(vola_convert(path, &options, &none, NULL) == VOLA_ERROR_INVALID_ARGUMENT);
  vola_tree_free(tree);
  vola_tree_free(NULL);
  CHECK(strcmp(vola_status_string(VOLA_ERROR_FORMAT), "format error") == 0);
  CHECK(strlen(vola_version()) > 0);
}

/* The point records of a LAS file (malloc'd, *size bytes), or NULL. */
static unsigned char *las_records(const char *path, size_t *size) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  unsigned char header[375];
  size_t got = fread(header, 1, sizeof header, f);
  unsigned char *records = NULL;
  if (got == sizeof header) {
    uint32_t offset, count32;
    uint16_t length;
    uint64_t count;
    memcpy(&offset, header + 96, 4);
    memcpy(&length, header + 105, 2);
    memcpy(&count32, header + 107, 4);
    memcpy(&count, header + 247, 8);
    if (count32) count = count32;
    *size = (size_t)count * length;
    records = malloc(*size ? *size : 1);
    if (records && (fseek(f, (long)offset, SEEK_SET) != 0 || fread(records, 1, *size, f) != *size)) {
      free(records);
      records = NULL;
    }
  }
  fclose(f);
  return records;
}

/* A tree's voxels out as LAS and LAZ, the LAZ back to LAS by vola_translate: the same records. */
static void test_points_out(const char *scratch, const char *vol) {
  char las[4096], laz[4096], back[4096];
  snprintf(las, sizeof las, "%s/points.las", scratch);
  snprintf(laz, sizeof laz, "%s/points.laz", scratch);
  snprintf(back, sizeof back, "%s/back.las", scratch);
  vola_tree *tree = NULL;
  CHECK_OK(vola_open(vol, VOLA_OPEN_MAPPED, &tree));
  if (!tree) return;
  CHECK_OK(vola_export_las(tree, las));
  CHECK_OK(vola_export_las(tree, laz));
  CHECK_OK(vola_translate(laz, back));
  size_t a_size = 0, b_size = 0;
  unsigned char *a = las_records(las, &a_size), *b = las_records(back, &b_size);
  CHECK(a && b && a_size > 0 && a_size == b_size && memcmp(a, b, a_size) == 0);
  free(a);
  free(b);
  CHECK(strcmp(vola_last_warnings(), "") == 0); /* LAZ to LAS keeps everything */
  CHECK(vola_translate(laz, NULL) == VOLA_ERROR_INVALID_ARGUMENT);
  CHECK(vola_translate(vol, back) == VOLA_ERROR_INVALID_ARGUMENT);  /* a .vol is not a point file */
  vola_tree_free(tree);
}

/* A survey with a CRS to XYZ, which has no place for it: said through vola_last_warnings,
 * as the CLI says it; a LAS output keeps the CRS and warns about nothing. */
static void test_translate_warnings(const char *scratch, const char *las_with_crs) {
  char xyz[4096], las[4096];
  snprintf(xyz, sizeof xyz, "%s/crs.xyz", scratch);
  snprintf(las, sizeof las, "%s/crs.las", scratch);
  CHECK_OK(vola_translate(las_with_crs, xyz));
  CHECK(strstr(vola_last_warnings(), "crs.xyz: XYZ has no place for the CRS") != NULL);
  CHECK(vola_translate(las_with_crs, NULL) == VOLA_ERROR_INVALID_ARGUMENT);
  CHECK(strcmp(vola_last_warnings(), "") == 0); /* a failed call leaves no warnings behind */
  CHECK_OK(vola_translate(las_with_crs, xyz));
  CHECK_OK(vola_translate(las_with_crs, las));
  CHECK(strcmp(vola_last_warnings(), "") == 0);
}

/* A state map (vola map) opens as its occupied voxels, as the CLI reads it; with
 * VOLA_OPEN_STATES as every known voxel (free ones were obstacles to C callers). */
static void test_state_map(const char *map, uint64_t occupied) {
  for (int mode = 0; mode < 2; ++mode) {
    vola_tree *obstacles = NULL, *states = NULL;
    CHECK_OK(vola_open(map, mode ? VOLA_OPEN_MAPPED : VOLA_OPEN_READ, &obstacles));
    CHECK_OK(vola_open(map, (mode ? VOLA_OPEN_MAPPED : VOLA_OPEN_READ) | VOLA_OPEN_STATES, &states));
    if (!obstacles || !states) return;
    vola_info a, b;
    CHECK_OK(vola_get_info(obstacles, &a));
    CHECK_OK(vola_get_info(states, &b));
    CHECK(a.voxel_count == occupied && occupied > 0);
    CHECK(b.voxel_count > a.voxel_count);
    vola_tree_free(obstacles);
    vola_tree_free(states);
  }
  vola_tree *none = NULL;
  CHECK(vola_open(map, 4, &none) == VOLA_ERROR_INVALID_ARGUMENT && none == NULL);
}

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: test_capi SCRATCH_DIR [FILE_WITH_ATTRIBUTES.vol [LAS_WITH_CRS [STATE_MAP.vol OCCUPIED_VOXELS]]]\n");
    return 2;
  }
  test_build_query_iterate(argv[1]);
  test_points_and_attributes();
  if (argc > 2) test_shared_file(argv[2]);
  if (argc > 2) test_points_out(argv[1], argv[2]);
  if (argc > 3) test_translate_warnings(argv[1], argv[3]);
  if (argc > 5) test_state_map(argv[4], strtoull(argv[5], NULL, 10));
  test_errors(argv[1]);
  test_cut_while_mapped(argv[1]);
  if (failures) {
    fprintf(stderr, "%d checks failed\n", failures);
    return 1;
  }
  printf("test_capi: all checks passed\n");
  return 0;
}
