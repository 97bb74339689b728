// vola info on point files (LAS, LAZ, COPC) as well as .vol files.
#pragma once

#include <string>

namespace vola::cli {

// An Entwine Point Tiles dataset (its ept.json): version, data type, points, CRS, bounds,
// schema and the hierarchy's nodes and points per depth, from the JSON alone; with
// `summary`, every node read too.
void print_ept_info(const std::string& path, bool summary, bool json);
// Whether the file starts with a LAS signature ("LASF"): LAS, LAZ and COPC files.
bool is_point_file(const std::string& path);
// The header, (E)VLRs, CRS, compression and COPC octree of a LAS/LAZ/COPC file; with
// `summary`, every point read too (count, bounds, column ranges, points per class).
void print_point_file_info(const std::string& path, bool summary, bool json);
// Any other file vola reads: a point file (PLY, PCD, XYZ, NPY, KITTI): count, CRS,
// columns; with `summary`, bounds, column ranges and points per class. A mesh (triangles),
// a voxel grid or map (binvox, NPY occupancy, OctoMap, OpenVDB: dims, cell size, occupied
// cells) or a DEM (cells with a height): what vola convert reads, with its CRS and bounds.
// `json`: the same as one JSON object on stdout (pdal info --summary's content). `part`:
// the grid of an OpenVDB file or the array of an .npz archive to show (empty: the default).
void print_point_cloud_info(const std::string& path, bool summary, bool json, const std::string& part = {},
                            const std::string& format = "auto");

}  // namespace vola::cli
