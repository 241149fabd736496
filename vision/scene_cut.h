// The subject cut out of a busy scene when no clean plate was given. The border-colour model
// (vision/foreground.h) takes every colour not seen on the photo's borders for the subject: fine
// before a curtain, wrong in a room, where the whole scene then joins the head's blob. Here the
// face placed by the detector and the landmark network seeds OpenCV's GrabCut (Rother et al.
// 2004, "GrabCut: interactive foreground extraction using iterated graph cuts"): the inner face
// is surely subject, the head's core probably, a halo where big hair may reach probably not, the
// scene beyond surely not. The side photo shows no face a detector finds; the front's subject
// colours place the head in it, on the rows the front's head spans.
#pragma once

#include <opencv2/core.hpp>

namespace orthoface::vision {

// How much of the border-colour blob `mask` (CV_8U 0 / 255; may be empty) lies where a head
// around `face` (the face's box in the same photo: brows to chin, cheek to cheek) cannot reach,
// above the shoulders: the blob's pixels more than 1.7 face widths beside the face's centre, on
// rows from the image top to half a face height below the chin, over the face box's area. 0 for
// a blob that is the head and body; more than kSceneSpill when the scene joined the blob. 1 when
// the blob is empty, misses the face's centre or covers less than 80 % of the face's middle
// three fifths (the face's colours were taken for the scene's). Throws std::invalid_argument on
// an empty `face` box or a mask that is not CV_8U.
inline constexpr double kSceneSpill = 0.25;
double scene_spill(const cv::Mat& mask, const cv::Rect2d& face);

// The front blob's widest row over the side blob's deepest on the face's rows, from the face
// box's top to 0.7 of its height (`face` as for scene_spill, in the front photo; `row_scale`:
// front rows per side row). A head is longer, front to back, than it is wide (the cephalic index
// reaches about 0.9), hair included: on the 26 FRMDB pairs 0.73-1.07, sim heads 0.88-0.98. A
// front blob that an object on the desk behind joined (a disc beside the cheek) is wider: 1.26.
// 0 when either mask is empty or holds none of those rows. Throws std::invalid_argument on an
// empty face box, a mask that is not CV_8U or a row_scale that is not positive.
inline constexpr double kSceneWidthToDepth = 1.15;
double head_width_to_depth(const cv::Mat& front_mask, const cv::Mat& side_mask,
                           const cv::Rect2d& face, double row_scale);

struct SceneCut {
  cv::Mat probability;  // CV_32F 0..1, the cut smoothed by a pixel (as foreground_probability)
  cv::Mat mask;         // CV_8U 0 / 255, the subject's blob, holes filled; empty when none
};

// The subject in the front photo around `face` (as for scene_spill). `border` (optional): the
// photo's foreground_probability without a plate; where it says background, the subject's
// colour model does not start. Throws std::invalid_argument when `front` is not 8-bit BGR,
// `face` is empty or off the photo, or `border` is not a CV_32F map of the photo's size.
SceneCut cut_front(const cv::Mat& front, const cv::Rect2d& face, const cv::Mat& border = {});

// What the front photo's cut tells the side photo: the head's rows (side photo rows), its width
// (side photo pixels) and the subject's colours.
struct SideHint {
  double top = 0, chin = 0;  // crown and chin rows
  double eyes = 0;           // the eyes' row
  double head_width = 0;     // the head's width at the eyes, hair included
  cv::Mat colours;  // CV_32F 1 x kColourBins histogram (vision/foreground.h) of the subject's head,
                    // sums to 1
};
// `mask`: the front's subject (a cut or the border-colour blob); `row_scale`: front rows per
// side row. Throws std::invalid_argument when `front` is not 8-bit BGR, the mask is not the
// photo's size or does not reach the eyes' row, or row_scale is not positive.
SideHint side_hint(const cv::Mat& front, const cv::Mat& mask, const cv::Rect2d& face,
                   double row_scale);

// How much of the subject's colour the side blob `mask` leaves out where the head is: of the side
// photo's pixels whose colour is mostly the subject's (vision/scene_cut.cpp), on the rows from
// the eyes to the chin and a head's depth of columns around where those colours gather, the
// share outside the mask. Near 0 when the blob holds the head; large when the border colours
// took the face for the scene (skin-coloured walls, wood). 1 for an empty mask. Throws
// std::invalid_argument on a bad photo, hint or mask (not CV_8U of the photo's size).
inline constexpr double kSideMissed = 0.15;
double side_missed(const cv::Mat& side, const cv::Mat& mask, const SideHint& hint);

// The subject in the side photo: the head placed where the subject's colours gather on the rows
// the hint gives, then cut as the front. Throws std::invalid_argument when `side` is not 8-bit
// BGR, the hint is not a head (no rows, no width) or `border` is bad (as for cut_front).
SceneCut cut_side(const cv::Mat& side, const SideHint& hint, const cv::Mat& border = {});

}  // namespace orthoface::vision
