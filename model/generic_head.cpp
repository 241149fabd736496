#include "model/generic_head.h"

#include <stdexcept>

#include <nlohmann/json.hpp>

namespace orthoface::model::detail {
namespace {

GenericHead parse_generic_head() {
  GenericHead g;
  try {
    const nlohmann::json j = nlohmann::json::parse(kGenericHeadJson);
    g.rows = j.at("rows").get<int>();
    g.half_rays = j.at("half_rays").get<int>();
    g.top = j.at("top").get<double>();
    g.bottom = j.at("bottom").get<double>();
    const auto& c = j.at("contour");
    if (g.rows < 2 || g.half_rays < 2 || !(g.top > g.bottom) || int(c.size()) != g.rows)
      throw std::logic_error("inconsistent table size");
    for (const auto& row : c) {
      if (int(row.size()) != g.half_rays) throw std::logic_error("a row of the wrong length");
      for (const auto& p : row) g.contour.push_back({p.at(0).get<double>(), p.at(1).get<double>()});
    }
    for (const auto& [name, p] : j.at("landmarks").items())
      g.landmarks.emplace_back(name, Eigen::Vector3d(p.at(0).get<double>(), p.at(1).get<double>(),
                                                     p.at(2).get<double>()));
  } catch (const std::exception& e) {
    throw std::logic_error(std::string("embedded generic head data: ") + e.what());
  }
  return g;
}

}  // namespace

const GenericHead& generic_head() {
  static const GenericHead g = parse_generic_head();
  return g;
}

}  // namespace orthoface::model::detail
