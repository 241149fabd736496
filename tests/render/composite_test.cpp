// The head removed from a photo and a view composited into it.
#include "render/composite.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace orthoface::render {
namespace {

// A scene: a horizontal grey ramp, with a red disc (the head) in the middle.
struct Photo {
  cv::Mat scene, photo, head;
  Photo() {
    scene.create(120, 160, CV_8UC3);
    for (int y = 0; y < scene.rows; ++y)
      for (int x = 0; x < scene.cols; ++x) scene.at<cv::Vec3b>(y, x) = cv::Vec3b::all(uchar(x));
    photo = scene.clone();
    head = cv::Mat::zeros(scene.size(), CV_8U);
    cv::circle(head, {80, 60}, 25, cv::Scalar(255), cv::FILLED);
    photo.setTo(cv::Scalar(0, 0, 255), head);
  }
};

TEST(HeadRemoved, ACleanPlateGivesTheSceneBack) {
  const Photo p;
  const cv::Mat out = head_removed(p.photo, p.head, p.scene);
  EXPECT_EQ(cv::norm(out, p.scene, cv::NORM_INF), 0);
}

TEST(HeadRemoved, InpaintingFillsTheHoleFromItsSurroundings) {
  const Photo p;
  cv::Mat grown;  // the region past the disc's anti-aliased edge
  cv::dilate(p.head, grown, cv::getStructuringElement(cv::MORPH_ELLIPSE, {9, 9}));
  const cv::Mat out = head_removed(p.photo, grown);
  // No red is left, the fill follows the ramp roughly, and outside the region nothing moved.
  cv::Mat red;
  cv::inRange(out, cv::Scalar(0, 0, 200), cv::Scalar(80, 80, 255), red);
  EXPECT_EQ(cv::countNonZero(red), 0);
  EXPECT_NEAR(out.at<cv::Vec3b>(60, 80)[1], 80, 25);
  cv::Mat diff;
  cv::absdiff(out, p.photo, diff);
  diff.setTo(cv::Scalar::all(0), grown);
  EXPECT_EQ(cv::norm(diff, cv::NORM_INF), 0);
}

TEST(HeadRemoved, TheSubjectDoesNotBleedIntoTheFill) {
  Photo p;
  // A white body below the head: known to the photo, but not background.
  cv::Mat body = cv::Mat::zeros(p.photo.size(), CV_8U);
  cv::rectangle(body, cv::Rect(50, 80, 60, 40), cv::Scalar(255), cv::FILLED);
  p.photo.setTo(cv::Scalar::all(255), body & ~p.head);
  cv::Mat region, subject;
  cv::dilate(p.head, region, cv::Mat::ones(5, 5, CV_8U));
  cv::dilate(body | p.head, subject, cv::Mat::ones(5, 5, CV_8U));
  const cv::Mat with = head_removed(p.photo, region, {}, subject);
  const cv::Mat without = head_removed(p.photo, region);
  // Just above the body the fill is the ramp's grey with the subject known, whiter without.
  EXPECT_LT(with.at<cv::Vec3b>(78, 80)[0], 140);
  EXPECT_GT(without.at<cv::Vec3b>(78, 80)[0], with.at<cv::Vec3b>(78, 80)[0]);
}

TEST(Composite, TheViewOverTheBackgroundFadingBelowTheNeck) {
  const Photo p;
  RenderResult view;
  view.image = cv::Mat(p.scene.size(), CV_8UC3, cv::Scalar(0, 255, 0));
  view.mask = cv::Mat::zeros(p.scene.size(), CV_8U);
  view.mask.rowRange(20, 100).setTo(255);
  CompositeOptions o;
  o.feather_px = 0;
  o.fade_from_row = 60;
  o.fade_to_row = 80;
  const cv::Mat out = composite(view, p.scene, o);
  EXPECT_EQ(out.at<cv::Vec3b>(40, 30), cv::Vec3b(0, 255, 0));           // the view
  EXPECT_EQ(out.at<cv::Vec3b>(10, 30), p.scene.at<cv::Vec3b>(10, 30));  // outside its mask
  EXPECT_EQ(out.at<cv::Vec3b>(90, 30), p.scene.at<cv::Vec3b>(90, 30));  // faded out
  const cv::Vec3b mid = out.at<cv::Vec3b>(70, 30);                      // half way
  EXPECT_GT(mid[1], 100);
  EXPECT_LT(mid[1], 160);
}

TEST(Composite, FittedKeepsTheAspectAndCentres) {
  const cv::Mat image(100, 200, CV_8UC3, cv::Scalar::all(200));
  const cv::Mat f = fitted(image, 100, 100);
  ASSERT_EQ(f.size(), cv::Size(100, 100));
  EXPECT_EQ(f.at<cv::Vec3b>(10, 50), cv::Vec3b(0, 0, 0));  // letterbox
  EXPECT_EQ(f.at<cv::Vec3b>(50, 50), cv::Vec3b::all(200));
}

TEST(Composite, BadInputIsRefusedNamingIt) {
  const Photo p;
  auto message = [](auto f) {
    try {
      f();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const cv::Mat small(10, 10, CV_8U, cv::Scalar(0));
  EXPECT_NE(message([&] { head_removed(cv::Mat(), p.head); }).find("photo"), std::string::npos);
  EXPECT_NE(message([&] { head_removed(p.photo, small); }).find("region"), std::string::npos);
  EXPECT_NE(message([&] { head_removed(p.photo, p.head, small); }).find("clean plate"),
            std::string::npos);
  EXPECT_NE(message([&] { head_removed(p.photo, p.head, {}, small); }).find("subject"),
            std::string::npos);
  RenderResult view;
  view.image = p.photo;
  view.mask = p.head;
  EXPECT_NE(message([&] { composite(view, small); }).find("background"), std::string::npos);
  CompositeOptions o;
  o.fade_from_row = 50;
  o.fade_to_row = 40;
  EXPECT_NE(message([&] { composite(view, p.scene, o); }).find("fade_to_row"), std::string::npos);
  o = {};
  o.feather_px = -1;
  EXPECT_NE(message([&] { composite(view, p.scene, o); }).find("feather_px"), std::string::npos);
  EXPECT_NE(message([&] { fitted(cv::Mat(), 10, 10); }).find("empty"), std::string::npos);
  EXPECT_NE(message([&] { fitted(p.photo, 0, 10); }).find("size"), std::string::npos);
}

}  // namespace
}  // namespace orthoface::render
