#include "analysis/mpeg4_names.h"

#include <stdexcept>

namespace orthoface::analysis {

const std::vector<Mpeg4Name>& mpeg4_names() {
  static const std::vector<Mpeg4Name> kNames = {
      {"2.1", "bottom of the chin"},
      {"2.2", "middle point of inner upper lip contour"},
      {"2.3", "middle point of inner lower lip contour"},
      {"2.4", "left corner of inner lip contour"},
      {"2.5", "right corner of inner lip contour"},
      {"2.10", "chin boss"},
      {"2.11", "chin left corner"},
      {"2.12", "chin right corner"},
      {"2.13", "left corner of jaw bone"},
      {"2.14", "right corner of jaw bone"},
      {"3.1", "center of upper inner left eyelid"},
      {"3.2", "center of upper inner right eyelid"},
      {"3.3", "center of lower inner left eyelid"},
      {"3.4", "center of lower inner right eyelid"},
      {"3.5", "center of the pupil of left eye"},
      {"3.6", "center of the pupil of right eye"},
      {"3.7", "outer corner of left eye"},
      {"3.8", "inner corner of right eye"},
      {"3.11", "inner corner of left eye"},
      {"3.12", "outer corner of right eye"},
      {"4.1", "inner corner of left eyebrow"},
      {"4.2", "inner corner of right eyebrow"},
      {"4.3", "uppermost point of the left eyebrow"},
      {"4.4", "uppermost point of the right eyebrow"},
      {"4.5", "outer corner of left eyebrow"},
      {"4.6", "outer corner of right eyebrow"},
      {"5.1", "center of the left cheek"},
      {"5.2", "center of the right cheek"},
      {"5.3", "left cheek bone"},
      {"5.4", "right cheek bone"},
      {"8.1", "middle point of outer upper lip contour"},
      {"8.2", "middle point of outer lower lip contour"},
      {"8.3", "left corner of outer lip contour"},
      {"8.4", "right corner of outer lip contour"},
      {"9.1", "left nostril border"},
      {"9.2", "right nostril border"},
      {"9.3", "nose tip"},
      {"9.4", "bottom right edge of nose"},
      {"9.5", "bottom left edge of nose"},
      {"9.6", "right upper edge of nose bone"},
      {"9.7", "left upper edge of nose bone"},
      {"9.12", "middle lower edge of nose bone"},
      {"9.15", "bottom middle edge of nose"},
      {"10.1", "top of left ear"},
      {"10.2", "top of right ear"},
      {"10.3", "back of left ear"},
      {"10.4", "back of right ear"},
      {"10.5", "bottom of left ear lobe"},
      {"10.6", "bottom of right ear lobe"},
      {"10.7", "lower contact point between left lobe and face"},
      {"10.8", "lower contact point between right lobe and face"},
      {"10.9", "upper contact point between left ear and face"},
      {"10.10", "upper contact point between right ear and face"},
      {"11.1", "middle border between hair and forehead"},
      {"11.2", "right border between hair and forehead"},
      {"11.3", "left border between hair and forehead"},
      {"11.4", "top of skull"},
      {"11.6", "back of skull"},
  };
  return kNames;
}

bool is_mpeg4_name(std::string_view name) {
  for (const auto& n : mpeg4_names())
    if (n.name == name) return true;
  return false;
}

const std::vector<Mpeg4Name>& helper_point_names() {
  static const std::vector<Mpeg4Name> names = {
      {"nasion", "deepest point between the eyes (helper)"},
      {"sulcus", "mentolabial sulcus (helper)"}};
  return names;
}

bool is_feature_point_name(std::string_view name) {
  if (is_mpeg4_name(name)) return true;
  for (const auto& n : helper_point_names())
    if (n.name == name) return true;
  return false;
}

std::string mpeg4_description(std::string_view name) {
  for (const auto& n : mpeg4_names())
    if (n.name == name) return std::string(n.description);
  for (const auto& n : helper_point_names())
    if (n.name == name) return std::string(n.description);
  throw std::invalid_argument("mpeg4_description: unknown MPEG-4 feature point '" +
                              std::string(name) + "'");
}

}  // namespace orthoface::analysis
