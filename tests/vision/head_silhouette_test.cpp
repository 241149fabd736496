// The subject's silhouette grown from vision's blob into the hair the blob missed.
#include "vision/head_silhouette.h"

#include <gtest/gtest.h>

#include <random>
#include <thread>

#include <opencv2/imgproc.hpp>

namespace orthoface::vision {
namespace {

// A photo of a head before a blue curtain: a skin face (the blob vision found) under brown hair
// (missed), eyes 60 px apart at row 200.
struct Photo {
  cv::Mat image, face, hair;
  explicit Photo(bool side) {
    image.create(480, 640, CV_8UC3);
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0, 6);
    for (int y = 0; y < image.rows; ++y)
      for (int x = 0; x < image.cols; ++x)
        image.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<uchar>(110 + noise(rng)),
                                              cv::saturate_cast<uchar>(70 + noise(rng)),
                                              cv::saturate_cast<uchar>(60 + noise(rng)));
    face = cv::Mat::zeros(image.size(), CV_8U);
    hair = cv::Mat::zeros(image.size(), CV_8U);
    const cv::Point centre = side ? cv::Point(300, 230) : cv::Point(320, 230);
    cv::ellipse(hair, side ? cv::Point(340, 170) : cv::Point(320, 170), {95, 80}, 0, 0, 360,
                cv::Scalar(255), cv::FILLED);
    cv::ellipse(face, centre, {70, 95}, 0, 0, 360, cv::Scalar(255), cv::FILLED);
    cv::rectangle(face, cv::Rect(centre.x - 40, 300, 80, 180), cv::Scalar(255), cv::FILLED);
    hair &= ~face;
    image.setTo(cv::Scalar(40, 60, 100), hair);
    image.setTo(cv::Scalar(120, 150, 210), face);
  }
};

FaceObservation observation() {
  FaceObservation o;
  o.front.width = o.side.width = 640;
  o.front.height = o.side.height = 480;
  o.front.features["eye_left_center"].px = {350, 200};
  o.front.features["eye_right_center"].px = {290, 200};
  o.centre_x_px = 320;
  o.centre_y_px = 240;
  o.side.features["nose_tip"].px = {235, 250};
  o.side_faces_left = true;
  return o;
}

double share(const cv::Mat& mask, const cv::Mat& region) {
  return double(cv::countNonZero(mask & region)) / std::max(1, cv::countNonZero(region));
}

TEST(SubjectSilhouettes, GrowTheBlobIntoTheHairItMissed) {
  const Photo front(false), side(true);
  FaceObservation o = observation();
  o.front_blob = front.face.clone();
  o.side_blob = side.face.clone();
  const Silhouettes s = subject_silhouettes(front.image, side.image, o);
  EXPECT_GT(share(s.front, front.hair), 0.9);
  EXPECT_GT(share(s.side, side.hair), 0.9);
  EXPECT_GT(share(s.front, front.face), 0.98);
  const cv::Mat background = ~(front.face | front.hair);
  EXPECT_LT(share(s.front, background), 0.02);
}

TEST(SubjectSilhouettes, WithoutTheEyesTheBlobsStayAsTheyAre) {
  const Photo front(false), side(true);
  FaceObservation o = observation();
  o.front.features.erase("eye_left_center");
  o.front_blob = front.face.clone();
  o.side_blob = side.face.clone();
  const Silhouettes s = subject_silhouettes(front.image, side.image, o);
  EXPECT_EQ(cv::countNonZero(s.front != front.face), 0);
  EXPECT_EQ(cv::countNonZero(s.side != side.face), 0);
}

// GrabCut's colour models start from k-means on the thread's cv::theRNG(): the silhouettes must
// not depend on what drew from it before (a batch's earlier pairs), and the caller's state stays.
TEST(SubjectSilhouettes, DoNotDependOnTheThreadsRandomState) {
  Photo front(false), side(true);
  // Speckled hair and curtain, so that k-means' start matters.
  cv::Mat speckle(front.image.size(), CV_8UC3);
  cv::RNG(11).fill(speckle, cv::RNG::UNIFORM, 0, 90);
  for (Photo* p : {&front, &side}) cv::add(p->image, speckle, p->image, ~p->face);
  FaceObservation o = observation();
  o.front_blob = front.face.clone();
  o.side_blob = side.face.clone();
  Silhouettes fresh;  // on a new thread: the RNG's default state
  std::thread([&] { fresh = subject_silhouettes(front.image, side.image, o); }).join();
  cv::RNG& rng = cv::theRNG();
  for (int i = 0; i < 1000; ++i) rng.next();
  const uint64 before = rng.state;
  const Silhouettes here = subject_silhouettes(front.image, side.image, o);
  EXPECT_EQ(rng.state, before);
  EXPECT_EQ(cv::countNonZero(here.front != fresh.front), 0);
  EXPECT_EQ(cv::countNonZero(here.side != fresh.side), 0);
}

TEST(SubjectSilhouettes, BadInputIsRefusedNamingIt) {
  const Photo front(false), side(true);
  const FaceObservation o = observation();
  cv::Mat small;
  cv::resize(front.image, small, {}, 0.5, 0.5);
  try {
    subject_silhouettes(small, side.image, o);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("front photo is 320x240, its observation 640x480"),
              std::string::npos);
  }
  cv::Mat grey;
  cv::cvtColor(side.image, grey, cv::COLOR_BGR2GRAY);
  EXPECT_THROW(subject_silhouettes(front.image, grey, o), std::invalid_argument);
  SilhouetteOptions bad;
  bad.iterations = 0;
  EXPECT_THROW(subject_silhouettes(front.image, side.image, o, bad), std::invalid_argument);
}

// A head (an ellipse 200 px wide, top at row 60) with a curtain fold standing on it: a column 60
// px wide from the top border down into the head's top (FRMDB 023's front). The column goes;
// of the head only the crown under it (rows 60..74, before the head is 90 px wide) can go with
// it; a crown cut by the top border (it widens at once) is left as it is.
TEST(TopColumn, AColumnOnTheHeadGoesAndACutCrownStays) {
  cv::Mat head(400, 400, CV_8U, cv::Scalar(0));
  cv::ellipse(head, cv::Point(200, 200), {100, 140}, 0, 0, 360, cv::Scalar(255), cv::FILLED);
  cv::Mat with_column = head.clone();
  with_column(cv::Rect(150, 0, 60, 70)).setTo(255);
  const cv::Mat cleaned = without_top_column(with_column, 30);
  EXPECT_EQ(cv::countNonZero(cleaned.row(0)), 0);
  EXPECT_EQ(cv::countNonZero(cleaned.rowRange(0, 55)), 0);
  EXPECT_EQ(cv::countNonZero(cleaned.rowRange(76, 400) != head.rowRange(76, 400)), 0);
  EXPECT_GT(cv::countNonZero(cleaned), 0.98 * cv::countNonZero(head));
  EXPECT_GT(cv::countNonZero(cleaned.row(70).colRange(216, 400)), 15);  // beside the column
  // A head whose crown the top border cuts: 200 px wide at row 0 and widening.
  cv::Mat cut(300, 400, CV_8U, cv::Scalar(0));
  cv::ellipse(cut, cv::Point(200, 120), {150, 180}, 0, 0, 360, cv::Scalar(255), cv::FILLED);
  EXPECT_EQ(cv::countNonZero(without_top_column(cut, 30) != cut), 0);
  // A subject off the top border, and a mask shorter than the rows asked for: as they are.
  EXPECT_EQ(cv::countNonZero(without_top_column(head, 30) != head), 0);
  EXPECT_EQ(cv::countNonZero(without_top_column(with_column.rowRange(0, 20), 30) !=
                             with_column.rowRange(0, 20)),
            0);
  // Bad input.
  EXPECT_THROW(without_top_column(cv::Mat(10, 10, CV_32F, cv::Scalar(1)), 5),
               std::invalid_argument);
  EXPECT_THROW(without_top_column(head, 1), std::invalid_argument);
  EXPECT_TRUE(without_top_column(cv::Mat(), 5).empty());
}

}  // namespace
}  // namespace orthoface::vision
