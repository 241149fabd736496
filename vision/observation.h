#pragma once

#include <limits>
#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace orthoface::vision {

// One named 2D point found in one view. Pixels, origin top-left of the image.
struct Feature2d {
  cv::Point2d px;
  double confidence = 0.0;  // 0 = guess from the position model only, 1 = certain
  std::string method;       // how it was found: "edge", "filter", "profile-curvature",
                            // "position-model", "mirrored", "haar", "dlib", ...
  bool mirrored = false;    // copied across the centre line from the other side (seed 004 §4)
};

// The face a photo shows, as vision::find_face finds it: dlib's face detector, then the landmark
// network on the widest face.
struct FoundFace {
  int faces = 0;     // faces scoring >= 0 at least half as wide as the widest
  cv::Rect2d box;    // the widest one, image pixels (empty when faces == 0)
  double score = 0;  // its detector score (0 is dlib's threshold; profiles score low)
  std::vector<cv::Point2d> points;  // the network's 68 points on it (iBUG); none without weights
  double turn = std::numeric_limits<double>::quiet_NaN();  // vision::turn_index of the points
};

// What vision found in one view.
struct ViewObservation {
  int width = 0;  // image size, pixels
  int height = 0;
  // Front view: the extremal boundary (face silhouette) as a polyline, top to bottom on the
  //   image-left side then the image-right side, each point with its own row.
  // Side view: the front half of the profile, forehead -> nose -> lips -> chin -> throat,
  //   ordered top to bottom.
  std::vector<cv::Point2d> boundary;
  double boundary_confidence = 0.0;
  std::map<std::string, Feature2d> features;  // names from vision/landmarks.h
};

// The observation of a front + side pair (seed 004 §4), in the images as given.
struct FaceObservation {
  ViewObservation front;
  ViewObservation side;
  // Front view centre line (symmetry axis): x = centre_x_px + tan(roll_rad) * (y - centre_y_px).
  double centre_x_px = 0.0;
  double centre_y_px = 0.0;
  double roll_rad = 0.0;
  double centre_confidence = 0.0;
  // True when the face in the side image looks toward the image left (the side camera stands at
  // the subject's left, head +x, as in DESIGN.md); false when it was mirrored (camera on the
  // right).
  bool side_faces_left = true;
  // How the side photo's profile looks by itself (vision::profile_faces_left, confidence 0..1),
  // and whether --side-camera decided side_faces_left instead; for the input check, not written
  // to observation.json.
  bool side_seen_faces_left = true;
  double side_seen_confidence = 0.0;
  bool side_camera_given = false;
  // The face the side photo shows (a profile usually none: dlib's detector reaches about 60
  // degrees); with --side-camera auto a clear one decides which way the profile looks. Not
  // written to observation.json.
  FoundFace side_face;
  // The head blobs vision cut out of each photo (CV_8U 0 / 255, vision::head_mask; empty when
  // none was found). Not written to observation.json.
  cv::Mat front_blob, side_blob;
  // The trained front landmarker's own points (names from vision/landmarks.h, front pixels),
  // before the consensus replaced any by the filters', with the user's front landmarks
  // (ObserveOptions::front_landmarks) in their place; empty when neither ran. The midline
  // features above sit on the centre line; these do not, so the head's turn shows in them.
  std::map<std::string, Feature2d> front_trained;
  // The trained front landmarker's 68 points (iBUG layout, vision/ibug68.h; front pixels) when
  // it found a plausible face, else empty. Not written to observation.json.
  std::vector<cv::Point2d> front_points68;
  std::vector<std::string> warnings;  // what is missing or doubtful, for report.json
};

// The feature named `name` in `features`, or nullptr.
inline const Feature2d* find_feature(const std::map<std::string, Feature2d>& features,
                                     const std::string& name) {
  const auto it = features.find(name);
  return it == features.end() ? nullptr : &it->second;
}

}  // namespace orthoface::vision
