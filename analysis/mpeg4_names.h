#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace orthoface::analysis {

// The MPEG-4 facial definition points (ISO/IEC 14496-2 Annex C) that lie on the head surface:
// groups 2 (chin, inner lips), 3 (eyes), 4 (brows), 5 (cheeks), 8 (outer lips), 9 (nose),
// 10 (ears), 11 (hairline, skull). Teeth and tongue points are left out. "left" is the
// subject's left (head +x).
struct Mpeg4Name {
  std::string_view name;         // "9.3"
  std::string_view description;  // "nose tip"
};
const std::vector<Mpeg4Name>& mpeg4_names();

// True when `name` is in mpeg4_names().
bool is_mpeg4_name(std::string_view name);

// The helper points `features` finds besides the MPEG-4 ones (on the mid-plane profile):
// "nasion" (the deepest point between the eyes) and "sulcus" (the mentolabial sulcus).
const std::vector<Mpeg4Name>& helper_point_names();

// True for an MPEG-4 name or a helper point name: every name `features` writes.
bool is_feature_point_name(std::string_view name);

// Description of an MPEG-4 or helper point; throws std::invalid_argument for an unknown name.
std::string mpeg4_description(std::string_view name);

}  // namespace orthoface::analysis
