// Everything of the core library in one include.
#pragma once

#include "vola/attributes.hpp"
#include "vola/builder.hpp"
#include "vola/error.hpp"
#include "vola/file.hpp"
#include "vola/frame.hpp"
#include "vola/output_file.hpp"
#include "vola/key.hpp"
#include "vola/setops.hpp"
#include "vola/stream_builder.hpp"
#include "vola/tree.hpp"
#include "vola/version.hpp"
#include "vola/voxel_reducer.hpp"
