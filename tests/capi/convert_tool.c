/* convert_tool INPUT OUTPUT [key=value ...]: vola_convert_file from C, for
 * tests/convert_equivalence.py. Keys are vola_convert_options' members (Python's keyword
 * names); lists are comma-separated: bbox=0,0,0,15,15,15 text_attributes=a=4:u8,b=5, but
 * filters, whose stages hold commas, are separated by semicolons: filters=smrf;hag. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vola/vola.h"

enum { kMaxItems = 64 };

static int split_doubles(const char *text, double *out, int capacity) {
  int n = 0;
  const size_t size = strlen(text) + 1;
  char *copy = malloc(size);
  if (!copy) return 0;
  memcpy(copy, text, size);
  for (char *item = strtok(copy, ","); item && n < capacity; item = strtok(NULL, ",")) out[n++] = strtod(item, NULL);
  free(copy);
  return n;
}

/* Text attribute specs hold no commas, so a comma separates them; filter stages do. */
static size_t split_strings(char *text, const char *separator, char **out, size_t capacity) {
  size_t n = 0;
  for (char *item = strtok(text, separator); item && n < capacity; item = strtok(NULL, separator)) out[n++] = item;
  return n;
}

int main(int argc, char **argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: convert_tool INPUT OUTPUT [key=value ...]\n");
    return 2;
  }
  vola_convert_options options;
  vola_convert_options_init(&options);
  int payload_columns[kMaxItems];
  char *text_attributes[kMaxItems];
  char *filters[kMaxItems];
  double values[kMaxItems];
  for (int i = 3; i < argc; ++i) {
    char *eq = strchr(argv[i], '=');
    if (!eq) {
      fprintf(stderr, "convert_tool: '%s' is not key=value\n", argv[i]);
      return 2;
    }
    *eq = '\0';
    const char *key = argv[i], *value = eq + 1;
    if (strcmp(key, "format") == 0) {
      options.format = value;
    } else if (strcmp(key, "quantize") == 0) {
      options.quantization = strcmp(value, "grid") == 0 ? VOLA_QUANTIZE_GRID : VOLA_QUANTIZE_TOOLKIT;
    } else if (strcmp(key, "depth") == 0) {
      options.depth = atoi(value);
    } else if (strcmp(key, "voxel_size") == 0) {
      options.voxel_size = strtod(value, NULL);
    } else if (strcmp(key, "origin") == 0) {
      options.has_origin = split_doubles(value, options.origin, 3) == 3;
    } else if (strcmp(key, "bbox") == 0) {
      options.has_bbox = split_doubles(value, options.bbox, 6) == 6;
    } else if (strcmp(key, "nbits") == 0) {
      options.nbits = atoi(value);
    } else if (strcmp(key, "epsg") == 0) {
      options.epsg = (uint32_t)strtoul(value, NULL, 10);
    } else if (strcmp(key, "assign_crs") == 0) {
      options.assign_crs = value;
    } else if (strcmp(key, "target_crs") == 0) {
      options.target_crs = value;
    } else if (strcmp(key, "allow_geographic") == 0) {
      options.allow_geographic = atoi(value);
    } else if (strcmp(key, "level") == 0) {
      options.level = atoi(value);
    } else if (strcmp(key, "grid") == 0) {
      options.grid = value;
    } else if (strcmp(key, "attributes") == 0) {
      options.attributes = atoi(value);
    } else if (strcmp(key, "columns") == 0) {
      const int n = split_doubles(value, values, 3);
      for (int c = 0; c < n; ++c) options.columns[c] = (int)values[c];
    } else if (strcmp(key, "payload_columns") == 0) {
      const int n = split_doubles(value, values, kMaxItems);
      for (int c = 0; c < n; ++c) payload_columns[c] = (int)values[c];
      options.payload_columns = payload_columns;
      options.payload_column_count = (size_t)n;
    } else if (strcmp(key, "filters") == 0) {
      options.filter_count = split_strings(eq + 1, ";", filters, kMaxItems);
      options.filters = (const char *const *)filters;
    } else if (strcmp(key, "text_attributes") == 0) {
      options.text_attribute_count = split_strings(eq + 1, ",", text_attributes, kMaxItems);
      options.text_attributes = (const char *const *)text_attributes;
    } else if (strcmp(key, "skip_lines") == 0) {
      options.skip_lines = atoi(value);
    } else if (strcmp(key, "solid") == 0) {
      options.solid = atoi(value);
    } else if (strcmp(key, "dem_base") == 0) {
      options.has_dem_base = 1;
      options.dem_base = strtod(value, NULL);
    } else if (strcmp(key, "dem_surface_only") == 0) {
      options.dem_surface_only = atoi(value);
    } else if (strcmp(key, "map_height") == 0) {
      options.map_height = strtod(value, NULL);
    } else if (strcmp(key, "dense") == 0) {
      if (atoi(value)) options.write_flags |= VOLA_WRITE_DENSE;
    } else if (strcmp(key, "compress") == 0) {
      if (atoi(value)) options.write_flags |= VOLA_WRITE_COMPRESS;
    } else if (strcmp(key, "compress_max") == 0) {
      if (atoi(value)) options.write_flags |= VOLA_WRITE_COMPRESS_MAX;
    } else {
      fprintf(stderr, "convert_tool: unknown option '%s'\n", key);
      return 2;
    }
  }
  vola_convert_report report;
  const vola_status status = vola_convert_file(argv[1], argv[2], &options, &report);
  if (status != VOLA_OK) {
    fprintf(stderr, "convert_tool: %s: %s\n", vola_status_string(status), vola_last_error());
    return 1;
  }
  return 0;
}
