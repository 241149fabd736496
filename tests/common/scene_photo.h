#pragma once
// A stand-in for a photograph of a room, made in the test: a coarse grid of random colours
// blended smoothly (walls, furniture and shelves out of focus behind the subject) with sensor
// grain. Its border holds well over a hundred of the border model's colours (a curtain: a
// handful), without the hard-edged shapes of sim's drawn clutter.

#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace orthoface::testing {

inline cv::Mat scene_photo(int seed, cv::Size size = {800, 600}) {
  cv::RNG rng(static_cast<std::uint64_t>(seed) * 2654435761u + 1u);
  cv::Mat grid(7, 9, CV_8UC3);
  rng.fill(grid, cv::RNG::UNIFORM, 20, 235);
  cv::Mat photo;
  cv::resize(grid, photo, size, 0, 0, cv::INTER_LINEAR);
  cv::Mat grain(size, CV_16SC3);
  rng.fill(grain, cv::RNG::NORMAL, 0, 6);
  cv::add(photo, grain, photo, cv::noArray(), CV_8UC3);
  return photo;
}

// Writes scene_photo(seed) as a PNG at `path` and returns the path.
inline std::string write_scene_photo(const std::string& path, int seed) {
  cv::imwrite(path, scene_photo(seed));
  return path;
}

}  // namespace orthoface::testing
