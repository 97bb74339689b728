// Column names of point formats that name their own fields (PCD fields, text headers):
// what vola calls them and how a voxel reduces them, so that a survey written by PDAL or
// CloudCompare converts and filters as its LAS does.
#pragma once

#include <string>
#include <string_view>

#include "vola/builder.hpp"

namespace vola::io {

// A field name as UTF-8: as it is when it is valid UTF-8, else each byte read as Latin-1
// (Windows-1252 spreadsheets write "Höhe" as "H\xf6he"), so that JSON reports, Python
// and the .vol's attribute names hold text, not bytes no decoder takes.
std::string utf8_name(std::string_view name);

// Lower case; LAS fields as PDAL spells them (ReturnNumber, GpsTime, PointSourceId, ...)
// under the LAS reader's names (return_number, gps_time, point_source_id, ...), and
// CloudCompare's R, G, B as red, green, blue. Other names stay as they are, lower case
// (and UTF-8, as utf8_name makes them).
std::string point_column_name(std::string_view field);

// Whether a field name, as the file spells it, names identifiers: "id", or a name ending
// in "ID"/"Id" after a lower-case letter, a digit or a separator (treeID, OriginId), or in
// "_id" (tree_id). Labels, not measurements: the mean of two ids is neither.
bool names_identifiers(std::string_view field);

// Classes (classification, class, label), clusters, segments, instances and identifiers
// (names_identifiers of `field`, the name as the file spells it) by majority,
// number_of_returns by maximum (as the LAS reader keeps them), the rest by mean.
// `column` is the name point_column_name gives it.
Reduction point_column_reduction(const std::string& column, std::string_view field);

}  // namespace vola::io
