// Finished new views (reconstruct/views.h) and the report text (report_json).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

#include "reconstruct/reconstruction.h"
#include "reconstruct/views.h"
#include "sim/head.h"
#include "sim/rig.h"
#include "tests/common/test_data.h"

namespace orthoface::reconstruct {
namespace {

namespace fs = std::filesystem;

// One sim subject reconstructed with its rig, shared by the tests of this file.
class Views : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const sim::Capture cap = sim::simulate_capture(sim::make_head(4), sim::RigOptions{});
    ReconstructOptions o;
    o.rig = cap.nominal_rig;
    rec_ = new Reconstruction(from_photos(cap.front, cap.side, o));
  }
  static void TearDownTestSuite() { delete rec_; }
  static Reconstruction* rec_;
};
Reconstruction* Views::rec_ = nullptr;

TEST_F(Views, DrawsTheFrontPhotosSizeOrTheAskedOne) {
  ViewRenderer photo(*rec_, {});
  const cv::Mat a = photo.image(30, 0);
  EXPECT_EQ(a.size(), rec_->front.size());
  EXPECT_EQ(a.type(), CV_8UC3);
  EXPECT_EQ(photo.options().synthesis.unseen, render::UnseenSide::MirrorView);  // landmark pairs

  ViewOptions o;
  o.width = 160;
  o.height = 120;
  o.background = parse_view_background("#ff0000");  // red: BGR (0, 0, 255)
  ViewRenderer red(*rec_, o);
  const FinishedView v = red.view(-20, 10);
  ASSERT_EQ(v.image.size(), cv::Size(160, 120));
  EXPECT_EQ(v.image.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 255));  // corner: the background
  EXPECT_EQ(v.view.mask.size(), cv::Size(160, 120));

  o.background = parse_view_background("transparent");
  ViewRenderer clear(*rec_, o);
  const cv::Mat t = clear.image(0, 0);
  ASSERT_EQ(t.type(), CV_8UC4);
  EXPECT_EQ(t.at<cv::Vec4b>(0, 0)[3], 0);
  EXPECT_EQ(t.at<cv::Vec4b>(60, 80)[3], 255);  // the face
}

// Drawn into the photo the lower neck twists into the unturned body; twist_neck false turns the
// whole head and neck as one. Above the chin the two views are the same.
TEST_F(Views, TheNeckTwistsIntoThePhotoUnlessAskedNotTo) {
  ViewOptions rigid_options;
  rigid_options.twist_neck = false;
  ViewRenderer twisted(*rec_, {}), rigid(*rec_, rigid_options);
  const FinishedView a = twisted.view(30, 0), b = rigid.view(30, 0);
  const double chin =
      capture::project(twisted.camera(30, 0), rec_->landmarks.at("chin_bottom")).y();
  const int above = std::clamp(int(chin) - 2, 1, a.image.rows);
  cv::Mat diff;
  cv::absdiff(a.image, b.image, diff);
  EXPECT_EQ(cv::countNonZero(diff.rowRange(0, above).reshape(1) > 2), 0);
  EXPECT_GT(cv::countNonZero(diff.rowRange(above, diff.rows).reshape(1) > 0), 1000);
}

TEST_F(Views, RefusesBadInput) {
  for (auto [w, h] : {std::pair{0, 100}, {100, 0}, {-1, 100}, {100, -5}, {9000, 100}}) {
    ViewOptions o;
    o.width = w;
    o.height = h;
    EXPECT_THROW(o.check(), std::invalid_argument) << w << "x" << h;
    EXPECT_THROW(ViewRenderer(*rec_, o), std::invalid_argument) << w << "x" << h;
  }
  ViewOptions colour;
  colour.background.kind = ViewBackground::Kind::Colour;
  colour.background.colour = {0, 300, 0};
  EXPECT_THROW(ViewRenderer(*rec_, colour), std::invalid_argument);

  Reconstruction no_photos = *rec_;
  no_photos.front = cv::Mat();
  try {
    ViewRenderer v(no_photos, {});
    ADD_FAILURE() << "no photos accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no photos"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ViewRenderer(Reconstruction{}, {}), std::invalid_argument);

  ViewOptions small;
  small.width = 80;
  small.height = 60;
  small.background = parse_view_background("black");
  ViewRenderer v(*rec_, small);
  for (auto [yaw, pitch] : {std::pair{181.0, 0.0},
                            {-200.0, 0.0},
                            {0.0, 90.0},
                            {0.0, -89.5},
                            {std::numeric_limits<double>::quiet_NaN(), 0.0}}) {
    EXPECT_THROW(v.view(yaw, pitch), std::invalid_argument) << yaw << " " << pitch;
  }
  EXPECT_NO_THROW(v.view(180, 89));

  // The one-off call gives the same image and refuses the same input.
  EXPECT_EQ(cv::norm(view_image(*rec_, small, 25, 5), v.image(25, 5), cv::NORM_INF), 0);
  EXPECT_THROW(view_image(*rec_, small, 200, 0), std::invalid_argument);
  EXPECT_THROW(view_image(no_photos, small, 0, 0), std::invalid_argument);
  ViewOptions negative;
  negative.width = -3;
  negative.height = 10;
  EXPECT_THROW(view_image(*rec_, negative, 0, 0), std::invalid_argument);
}

TEST_F(Views, UnseenSideFallsBackOrRefusesWithoutLandmarkPairs) {
  Reconstruction bare = *rec_;
  bare.landmarks.clear();
  ViewOptions o;
  o.width = 80;
  o.height = 60;
  o.background = parse_view_background("black");
  o.synthesis.unseen = render::UnseenSide::MirrorTexture;
  ViewRenderer fallback(bare, o);
  EXPECT_EQ(fallback.options().synthesis.unseen, render::UnseenSide::Front);
  o.unseen_fallback = false;
  try {
    ViewRenderer strict(bare, o);
    ADD_FAILURE() << "unseen texture without landmark pairs accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("texture"), std::string::npos) << e.what();
  }
}

TEST(ViewBackground, ParsesTheRenderCommandsNames) {
  EXPECT_EQ(parse_view_background("photo").kind, ViewBackground::Kind::Photo);
  EXPECT_EQ(parse_view_background("transparent").kind, ViewBackground::Kind::Transparent);
  EXPECT_EQ(parse_view_background("white").colour, cv::Scalar(255, 255, 255));
  EXPECT_EQ(parse_view_background("gray").colour, cv::Scalar(128, 128, 128));
  EXPECT_EQ(parse_view_background("#102030").colour, cv::Scalar(0x30, 0x20, 0x10));  // BGR
  EXPECT_EQ(parse_view_background("1,2,3").colour, cv::Scalar(3, 2, 1));
  for (const char* bad :
       {"", "purple", "#12345", "#1234567", "1,2", "1,2,300", "-1,2,3", "1,2,3,4", "Photo"}) {
    try {
      parse_view_background(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("'") + bad + "'"), std::string::npos)
          << e.what();
    }
  }
}

TEST_F(Views, ReportJsonIsTheReportFile) {
  const fs::path dir = testing::temp_dir("reconstruct_views_report") / "rec";
  write_reconstruction(*rec_, dir.string());
  std::ifstream f(dir / "report.json");
  const std::string file((std::istreambuf_iterator<char>(f)), {});
  EXPECT_EQ(report_json(*rec_), file);
  // An empty reconstruction still gives a well-formed report (no mesh, no findings).
  const std::string empty = report_json(Reconstruction{});
  EXPECT_NE(empty.find("\"vertices\": 0"), std::string::npos) << empty;
}

}  // namespace
}  // namespace orthoface::reconstruct
