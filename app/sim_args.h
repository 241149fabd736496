#pragma once

#include <string>

#include "sim/head.h"

namespace orthoface::app {

// The data folder of real scans: `flag_value` when given, else the build's default
// (ORTHOFACE_DATA_DIR, ../shared/data next to the source tree).
std::string data_dir(const std::string& flag_value);

// The real scan named `name` ("lee-perry-smith") from `data_dir`. Throws std::invalid_argument
// for an unknown name and std::runtime_error when the scan files are missing or corrupt.
sim::Head load_scan(const std::string& name, const std::string& data_dir);

}  // namespace orthoface::app
