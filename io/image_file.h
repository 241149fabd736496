// Image files and buffers decoded by OpenCV only when their first bytes are one of the image
// types the tools accept. cv::imread / cv::imdecode otherwise hand any bytes to whichever codec
// claims them (a DICOM file cut short made GDCM abort the process).
#pragma once

#include <cstddef>
#include <string>

#include <opencv2/core.hpp>

namespace orthoface::io {

// The types accepted, for error messages.
inline constexpr const char* kAcceptedImageTypes = "PNG, JPEG, BMP, TIFF, WebP or PNM/PGM/PPM";

// True when `bytes` begin with the signature of an accepted type (all 8 bytes of PNG's) and hold
// no DICOM marker at offset 128 (OpenCV tries its DICOM decoder before a codec whose signature
// does not match exactly). `size` may be smaller than the 132 bytes looked at.
bool accepted_image_bytes(const unsigned char* bytes, std::size_t size);

// accepted_image_bytes on the start of the file at `path`; false when it cannot be read.
bool accepted_image_file(const std::string& path);

// cv::imread / cv::imdecode for accepted bytes only: an empty Mat otherwise, as OpenCV gives for
// bytes it cannot decode, so every caller's "cannot be decoded" error covers both.
cv::Mat imread_accepted(const std::string& path, int flags);
cv::Mat imdecode_accepted(const cv::Mat& buffer, int flags);

}  // namespace orthoface::io
