// The subject's whole silhouette in each photo, hair included: the head blob (vision/foreground.h)
// separates colours unlike the photo's borders, so dark hair before a dark curtain is lost; here
// OpenCV's GrabCut (Rother et al. 2004) grows it into a head-sized box placed by the features.
#pragma once

#include <opencv2/core.hpp>

#include "vision/observation.h"

namespace orthoface::vision {

struct SilhouetteOptions {
  double work_width = 480;  // GrabCut runs on the photo scaled to this width (pixels, at most 1x)
  int iterations = 4;       // GrabCut iterations
  // The head's box from the eye distance E (pixels): the head reaches up to top_e x E above the
  // eyes; in the front photo half_width_e x E either side of the centre line; in the side photo
  // back_e x E behind the nose tip (and 0.4 E in front of it).
  double top_e = 2.6, half_width_e = 2.0, back_e = 4.2;
  void check() const;  // throws std::invalid_argument naming the bad field
};

// CV_8U 0 / 255 masks of the subject (head, hair, neck and whatever of the body the photo shows)
// in the front and the side photo: observation.front_blob / side_blob as definite subject, the
// head's box (placed by the front eyes, the centre line, and the side photo's nose tip) as
// possible subject, the rest as background. Where a blob or a feature is missing, that photo's
// blob is returned as it is (possibly empty). Throws std::invalid_argument when a photo is not
// 8-bit BGR or differs in size from its observation.
struct Silhouettes {
  cv::Mat front, side;
};
Silhouettes subject_silhouettes(const cv::Mat& front, const cv::Mat& side,
                                const FaceObservation& observation,
                                const SilhouetteOptions& options = {});

// `mask` (CV_8U, non-zero = subject) without a column standing on the head from the photo's top
// border: a fold of the curtain that the cut took for subject (FRMDB 023's front: 83 px wide for
// 40 rows and more, on a head 237 px wide) gives the head model a chimney. A column keeps its
// width: when the subject's rows from the top border down `rows` rows stay within 10 % of the top
// row's width, what lies within that width (widened by a tenth) is cleared from the top down to
// the first row half as wide again; the crown's pixels beside the column stay. A crown cut by the
// top border widens at once (026's side: 122 px at the border, 138 px 20 rows down) and is left
// as it is, as is a mask that does not touch the top border or has fewer than `rows` rows.
// subject_silhouettes applies it with `rows` half an eye distance. Throws std::invalid_argument
// when the mask is not CV_8U or `rows` < 2.
cv::Mat without_top_column(const cv::Mat& mask, int rows);

}  // namespace orthoface::vision
