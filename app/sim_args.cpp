#include "app/sim_args.h"

#include <filesystem>
#include <stdexcept>

#include "sim/scan.h"

namespace orthoface::app {

std::string data_dir(const std::string& flag_value) {
  if (!flag_value.empty()) return flag_value;
#ifdef ORTHOFACE_DEFAULT_DATA_DIR
  return ORTHOFACE_DEFAULT_DATA_DIR;
#else
  return "../shared/data";
#endif
}

sim::Head load_scan(const std::string& name, const std::string& data_dir) {
  if (name != "lee-perry-smith")
    throw std::invalid_argument("--scan: unknown scan '" + name + "' (known: lee-perry-smith)");
  const std::filesystem::path dir = std::filesystem::path(data_dir) / "lee_perry_smith_head";
  if (!std::filesystem::is_directory(dir))
    throw std::runtime_error("scan folder " + dir.string() + ": not found (see --data)");
  return sim::lee_perry_smith_head(dir.string());
}

}  // namespace orthoface::app
