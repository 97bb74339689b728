/* The VOLA C API: a stable C interface over the C++ library, for FFI users (ctypes,
 * Rust, Go, Julia) and C programs.
 *
 * - Trees are opaque handles (vola_tree *); free each with vola_tree_free.
 * - Every function that can fail returns a vola_status; VOLA_OK is 0. On failure the
 *   out-parameters are left untouched and vola_last_error() describes what went wrong
 *   (for a bad file: "<file>: byte <offset>: <cause>"), in this thread, until the next
 *   failing call in this thread.
 * - No C++ exception ever crosses this boundary: every entry point catches.
 * - A tree may be read from several threads at once (contains, iterate, write); it is
 *   never modified after it is made.
 *
 *     vola_tree *tree = NULL;
 *     if (vola_open("survey.vol", VOLA_OPEN_MAPPED, &tree) != VOLA_OK) {
 *       fprintf(stderr, "%s\n", vola_last_error());
 *       return 1;
 *     }
 *     int hit = 0;
 *     vola_contains(tree, 10, 20, 30, &hit);
 *     vola_tree_free(tree);
 *
 * Link with vola_c (CMake: target vola::vola_c).
 */
#ifndef VOLA_VOLA_H
#define VOLA_VOLA_H

#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32)
#  if defined(VOLA_C_BUILDING)
#    define VOLA_C_API __declspec(dllexport)
#  else
#    define VOLA_C_API __declspec(dllimport)
#  endif
#else
#  define VOLA_C_API __attribute__((visibility("default")))
#endif

#ifdef __cplusplus
extern "C" {
#endif

typedef enum vola_status {
  VOLA_OK = 0,
  VOLA_ERROR_INVALID_ARGUMENT = 1, /* a null pointer, depth out of 1..10, a voxel off the grid ... */
  VOLA_ERROR_FORMAT = 2,           /* the bytes are not a valid .vol file */
  VOLA_ERROR_IO = 3,               /* the operating system refused (open, map, write) */
  VOLA_ERROR_OUT_OF_MEMORY = 4,
  VOLA_ERROR_INTERNAL = 5          /* anything else; the message says what */
} vola_status;

typedef struct vola_tree vola_tree;

/* The message of this thread's last failure ("" when there was none). Valid until the
 * next failing call in this thread. */
VOLA_C_API const char *vola_last_error(void);
/* What this thread's last call of vola_convert, vola_convert_file or vola_translate warned
 * about, one warning a line, as the CLI prints them (e.g. "out.xyz: XYZ has no place for the
 * CRS of in.las ..."); "" when it warned about nothing or failed. Valid until the next of
 * those calls in this thread. */
VOLA_C_API const char *vola_last_warnings(void);
/* "ok", "invalid argument", "format error", "io error", "out of memory", "internal error". */
VOLA_C_API const char *vola_status_string(vola_status status);
/* The library version, e.g. "0.1.0". */
VOLA_C_API const char *vola_version(void);

/* ---- making trees ---- */

typedef enum vola_open_mode {
  VOLA_OPEN_READ = 0,  /* read the file into memory */
  VOLA_OPEN_MAPPED = 1, /* memory-map it: a sparse uncompressed file's levels are used in place */
  VOLA_OPEN_STATES = 2  /* or-ed with either: a state map as it is (see vola_open) */
} vola_open_mode;

/* A state map (`vola map`: occupied, free and unknown voxels) opens as its occupied voxels,
 * as every vola command reads it, unless VOLA_OPEN_STATES is or-ed into the mode: then
 * every known voxel, free ones too, is a voxel of the tree. */
VOLA_C_API vola_status vola_open(const char *path, int mode, vola_tree **out);

typedef enum vola_quantization {
  VOLA_QUANTIZE_TOOLKIT = 0, /* the reference's rounding against the bbox; needs a depth */
  VOLA_QUANTIZE_GRID = 1,    /* floor((p - origin) / voxel_size); depth and/or voxel size */
  VOLA_QUANTIZE_AUTO = 2     /* vola_convert only: grid when a voxel size or origin is given, else toolkit */
} vola_quantization;

typedef struct vola_build_options {
  vola_quantization quantization;
  int depth;          /* 1..10; 0 = grid mode: the smallest depth that covers the points */
  double voxel_size;  /* grid mode: the voxel edge; 0 = derived from the depth */
  uint32_t epsg;      /* recorded in the header; 0 = the reference's default (2000) */
} vola_build_options;

/* Points x0 y0 z0 x1 y1 z1 ... (count points). Non-finite points are dropped; *dropped (may
 * be NULL) receives how many. In grid mode the grid starts at the points' minimum, so no
 * point lies outside it: a depth too small for their extent at voxel_size is refused
 * (VOLA_ERROR_INVALID_ARGUMENT naming the depth that holds them), as is an extent no depth
 * up to 10 holds (one stray point far away does that: crop first, or vola_convert with a
 * bbox, whose grid drops what lies outside). */
VOLA_C_API vola_status vola_build_from_points(const double *xyz, size_t count, const vola_build_options *options,
                                              vola_tree **out, uint64_t *dropped);
/* Integer voxel coordinates x0 y0 z0 ..., each below 4^depth; duplicates allowed. */
VOLA_C_API vola_status vola_build_from_voxels(const uint32_t *xyz, size_t count, int depth, vola_tree **out);
/* The first `depth` levels as a coarser tree (shares no state with `tree` that the caller
 * must keep: `tree` may be freed first). */
VOLA_C_API vola_status vola_level_of_detail(const vola_tree *tree, int depth, vola_tree **out);
/* Frees a tree; NULL is allowed. */
VOLA_C_API void vola_tree_free(vola_tree *tree);

/* ---- writing ---- */

typedef enum vola_write_flags {
  VOLA_WRITE_SPARSE = 0,
  VOLA_WRITE_DENSE = 1,     /* the reference's dense layout (depth <= 5) */
  VOLA_WRITE_COMPRESS = 2,  /* zstd-compressed levels (vola's version-2 files; sparse only) */
  VOLA_WRITE_COMPRESS_MAX = 4 /* as COMPRESS, the occupancy coded by mixed models: smaller, slower to open */
} vola_write_flags;

/* flags: a vola_write_flags value. Writes through a temporary file and a rename. */
VOLA_C_API vola_status vola_write(const vola_tree *tree, const char *path, int flags);

/* ---- what a tree is ---- */

typedef struct vola_info {
  int depth;
  uint32_t side;          /* voxels per axis: 4^depth */
  uint64_t voxel_count;
  int mapped;             /* 1 when the levels live in a file mapping */
  int quantization;       /* a vola_quantization */
  double origin[3];       /* world position of voxel (0,0,0)'s corner */
  double voxel_size;      /* world size of a voxel */
  uint32_t epsg;
  size_t attribute_count;
} vola_info;

VOLA_C_API vola_status vola_get_info(const vola_tree *tree, vola_info *out);

/* ---- queries ---- */

/* *out = 1 when voxel (x, y, z) is occupied, else 0 (also for voxels off the grid). */
VOLA_C_API vola_status vola_contains(const vola_tree *tree, uint32_t x, uint32_t y, uint32_t z, int *out);
/* out[i] = contains(xyz[3i], xyz[3i+1], xyz[3i+2]) for i < count. */
VOLA_C_API vola_status vola_contains_many(const vola_tree *tree, const uint32_t *xyz, size_t count, uint8_t *out);
/* The voxel's index among all voxels in key order (its attribute row). VOLA_ERROR_INVALID_ARGUMENT
 * when the voxel is not occupied. */
VOLA_C_API vola_status vola_rank(const vola_tree *tree, uint32_t x, uint32_t y, uint32_t z, uint64_t *out);

/* ---- iteration ---- */

/* Called once per voxel in key order (the order of ranks). Return 0 to go on, anything
 * else to stop: vola_for_each_voxel then returns VOLA_OK and *visited (may be NULL) says
 * how many voxels were visited, the stopping one included. */
typedef int (*vola_voxel_callback)(uint32_t x, uint32_t y, uint32_t z, void *user);
VOLA_C_API vola_status vola_for_each_voxel(const vola_tree *tree, vola_voxel_callback callback, void *user,
                                           uint64_t *visited);
/* Copies up to `capacity` voxels starting at rank `first` into xyz (3 per voxel);
 * *written receives how many. For paging through a tree without a callback. */
VOLA_C_API vola_status vola_copy_voxels(const vola_tree *tree, uint64_t first, uint32_t *xyz, size_t capacity,
                                        size_t *written);

/* ---- converting files: the pipeline of `vola convert` (any input its readers know) ---- */

typedef void (*vola_progress_callback)(uint64_t done, uint64_t total, void *user);

/* Every option `vola convert` has. Start from vola_convert_options_init(): its defaults are
 * the CLI's. Column numbers count from 1. */
typedef struct vola_convert_options {
  const char *format;                  /* NULL or "auto": from the extension; else a reader's name */
  vola_quantization quantization;      /* default VOLA_QUANTIZE_AUTO */
  int depth;                           /* 1..10; 0 = grid mode: the smallest that covers the input */
  double voxel_size;                   /* grid mode: the voxel edge in input units; 0 = from the depth */
  int has_origin;                      /* origin: world position of voxel (0,0,0)'s corner (grid mode) */
  double origin[3];
  int has_bbox;                        /* bbox: min x y z, max x y z to quantize against */
  double bbox[6];
  int nbits;                           /* payload words per block: 0 or 1 (the reference's) */
  uint32_t epsg;                       /* the input's CRS as an EPSG code; 0 = what the input says */
  const char *target_crs;              /* NULL, or reproject points into this CRS (EPSG code, WKT, PROJ string) */
  int level;                           /* COPC: read octree levels 0..level only; -1 (default) = all */
  int attributes;                      /* keep the format's per-point attributes (default 1) */
  int columns[3]; /* text: x y z columns from 1; 0 0 0 (default): by a header's names, else 1 2 3 */
  const int *payload_columns;          /* text, nbits 1: payload byte columns (default: all after x y z) */
  size_t payload_column_count;
  const char *const *text_attributes;  /* text: "NAME=COLUMN[:TYPE[:REDUCTION]]" each */
  size_t text_attribute_count;
  int skip_lines;                      /* text: header lines to skip */
  int solid;                           /* meshes: fill the inside too */
  int has_dem_base;                    /* DEM: height the columns start from (default: lowest cell) */
  double dem_base;
  int dem_surface_only;                /* DEM: one voxel per cell, no columns */
  int write_flags;                     /* vola_convert_file: a vola_write_flags value */
  vola_progress_callback progress;     /* may be NULL; called now and then during long reads */
  void *progress_user;
  const char *assign_crs;              /* NULL, or the input's CRS as any definition (not with epsg) */
  int allow_geographic;                /* grid mode: voxelise in a geographic CRS's degrees anyway (default 0: refused;
                                          toolkit quantization, which has no voxel size, only warns) */
  const char *grid;                    /* OpenVDB: the grid to read; .npz: the array; NULL = the default */
  const char *const *filters;          /* point filter stages, run in order ("where:Classification == 2", */
  size_t filter_count;                 /* "smrf", "hag", "crop:X0,Y0,X1,Y1", ...: docs/FILTERS.md) */
  double map_height;                   /* ROS maps (MAP.yaml): occupied cells as columns this high; 0 = one voxel */
} vola_convert_options;

typedef struct vola_convert_report {
  uint64_t inputs;   /* points, triangles (meshes) or cells (DEM) read */
  uint64_t dropped;  /* outside the grid or not finite */
  uint64_t voxels;   /* occupied voxels out */
  uint32_t epsg;     /* the CRS's EPSG code when known, else 0 */
} vola_convert_report;

/* The CLI's defaults. */
VOLA_C_API void vola_convert_options_init(vola_convert_options *options);
/* Reads `input` and builds its tree as `vola convert` does (LAS streams: memory follows
 * voxels, not points). report may be NULL. */
VOLA_C_API vola_status vola_convert(const char *input, const vola_convert_options *options, vola_tree **out,
                                    vola_convert_report *report);
/* vola_convert, then vola_write(output, options->write_flags). */
VOLA_C_API vola_status vola_convert_file(const char *input, const char *output, const vola_convert_options *options,
                                         vola_convert_report *report);

/* ---- points out ---- */

/* The tree's voxel centres as LAS 1.4 (point format 6, or 7 with colour; attribute
 * columns into LAS fields and extra bytes; the CRS as WKT); a path ending in .laz is
 * LASzip-compressed; another extension is refused (VOLA_ERROR_INVALID_ARGUMENT). As
 * `vola export TREE OUT.las|.laz`. */
VOLA_C_API vola_status vola_export_las(const vola_tree *tree, const char *path);
/* Point file to point file, point by point, no voxels, as `vola translate IN OUT`: LAS,
 * LAZ, COPC, PLY, PCD, XYZ, NPY or KITTI in; LAS, LAZ, PLY or XYZ out (by extension). */
VOLA_C_API vola_status vola_translate(const char *input, const char *output);

/* ---- attributes ---- */

/* Name of attribute column `index` (< attribute_count), valid while the tree lives. */
VOLA_C_API vola_status vola_attribute_name(const vola_tree *tree, size_t index, const char **out);
/* The value of column `name` for the voxel of rank `rank`, as a double. */
VOLA_C_API vola_status vola_attribute_value(const vola_tree *tree, const char *name, uint64_t rank, double *out);

#ifdef __cplusplus
}
#endif

#endif /* VOLA_VOLA_H */
