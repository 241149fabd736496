#pragma once
// iBUG `.pts` landmark files (300-W, dlib, OpenFace), 68 points in the layout of vision/ibug68.h:
//
//   version: 1
//   n_points: 68
//   {
//   x y          (68 lines, point 0 first)
//   }
//
// Coordinates are pixels with the centre of the top-left pixel at (0, 0) (pixel indices, as
// dlib and OpenCV give them; 300-W's own annotations count from 1 and are 1 px off). Inside the
// program points follow capture/camera_model.h (pixel centre = index + 0.5): reading adds 0.5,
// writing subtracts it. A point that is not known is written as `-1 -1` and read back as
// missing; no known point can be (-1, -1), which lies outside the image.

#include <string>

#include "vision/ibug68.h"

namespace orthoface::vision {

// Writes `points` (capture convention) as a .pts file, all or nothing (io/atomic_file.h).
// Throws std::invalid_argument when a known point is not finite or is the missing marker itself
// (it would read back as missing), std::runtime_error naming the file when it cannot be written.
void write_pts(const Ibug68& points, const std::string& path);

// Reads a .pts file (capture convention; `-1 -1` = missing). Only n_points 68 is accepted.
// Throws std::runtime_error naming the file and what is wrong: unreadable, bad header, another
// point count, a missing brace, a non-numeric or non-finite coordinate, too few or too many
// points.
Ibug68 read_pts(const std::string& path);

// Throws std::invalid_argument naming `what` (e.g. the file) and the first known point outside
// a width x height image (capture convention: 0..width, 0..height).
void check_pts_in_image(const Ibug68& points, int width, int height, const std::string& what);

}  // namespace orthoface::vision
