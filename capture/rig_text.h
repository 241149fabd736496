#pragma once
// The text of a rig file as a tree: the subset of OpenCV's FileStorage YAML and XML that rig
// files use (capture/camera_model.h, capture/stereo_rig.h). Read by hand rather than through
// cv::FileStorage, whose 4.6 YAML parser never returns on some malformed files of a few dozen
// bytes (docs/fuzzing.md): this reader is linear in the file, nests at most kMaxRigDepth deep and
// refuses anything outside the subset with the line it stopped at.
//
// YAML: an optional `%YAML:1.0` / `%YAML 1.x` line and `---`; block mappings (`key: value`, one
// per line, nested by indentation); block sequences (`- item`); flow sequences and mappings
// (`[ 1, 2 ]`, `{ a: 1 }`, over several lines); plain, "double" and 'single' quoted scalars;
// `!!tag`s (kept, e.g. opencv-matrix); `#` comments. No anchors, aliases, multi-line plain or
// block scalars (| >), nor several documents.
// XML: `<?xml ...?>`, comments, a root element (opencv_storage) whose child elements are the
// keys; an element holds child elements (a mapping; `_` children make a sequence) or text
// (one token a scalar, several whitespace-separated tokens a sequence); type_id="..." is kept
// as the tag; &lt; &gt; &amp; &quot; &apos; are decoded. No CDATA, DOCTYPE or namespaces.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <functional>

#include <opencv2/core/mat.hpp>
#include <opencv2/core/persistence.hpp>

namespace orthoface::capture {

struct RigNode {
  enum class Kind { Scalar, Seq, Map };
  Kind kind = Kind::Scalar;
  std::string text;  // a scalar's value (quotes removed, escapes decoded)
  bool quoted = false;
  std::string tag;             // "opencv-matrix" for `!!opencv-matrix` or type_id="opencv-matrix"
  std::vector<RigNode> items;  // Seq
  struct Member;
  std::vector<Member> members;  // Map, in file order, keys unique
  int line = 0;                 // 1-based line where the node starts

  bool is_map() const { return kind == Kind::Map; }
  bool is_seq() const { return kind == Kind::Seq; }
  bool is_scalar() const { return kind == Kind::Scalar; }
  // The member named `key` of a mapping, nullptr when absent or this is not a mapping.
  const RigNode* find(const std::string& key) const;
  // A scalar that is a whole number in int range (no fraction, no exponent), else nullopt.
  std::optional<long long> as_int() const;
  // A scalar that is a number (YAML's .nan / .inf / -.inf included), else nullopt.
  std::optional<double> as_number() const;
};

struct RigNode::Member {
  std::string key;
  RigNode value;
};

inline constexpr int kMaxRigDepth = 8;  // a rig file nests 4 deep (file, camera, matrix, data)
inline constexpr std::size_t kMaxRigBytes = 1u << 20;  // a rig file is a few kB

// Parses `text` (YAML, or XML when its first non-blank character is '<'). Throws
// std::invalid_argument "line N: what" when it is over kMaxRigBytes, holds control bytes other
// than tab / CR / LF, nests deeper than kMaxRigDepth, repeats a key, or leaves the subset above.
// The top level is always a mapping.
RigNode parse_rig_text(const std::string& text);

// Reads and parses the file at `path`; std::runtime_error "rig file PATH: ..." for a missing or
// unreadable file or one parse_rig_text refuses.
RigNode read_rig_text(const std::string& path);

// An OpenCV matrix node (`!!opencv-matrix` / type_id="opencv-matrix": rows, cols, dt, data) as
// a CV_64F matrix. Throws std::invalid_argument saying what is wrong (the caller names the file
// and field): not a mapping, rows / cols not whole numbers of 1..16, dt not one channel of
// u c w s i f d, data not exactly rows x cols numbers. Non-finite values are returned as they are.
cv::Mat matrix_from_node(const RigNode& node);

// Writes a rig file all or nothing: `fill` writes its nodes into a cv::FileStorage in memory
// (XML when `path` ends in .xml, else YAML, the forms read_rig_text reads), and the text is then
// written with io::write_text_atomically, whose checks see a failed last flush (a full disk)
// that cv::FileStorage would not report. Throws std::runtime_error naming `path`.
void write_rig_text(const std::string& path, const std::function<void(cv::FileStorage&)>& fill);

}  // namespace orthoface::capture
