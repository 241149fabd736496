// orthoface enrol: one webcam instead of a two-camera rig. The person looks at the camera, then
// turns to a side; the best frontal and the best profile frame are picked from the head's
// estimated turn, saved, and reconstructed as `orthoface reconstruct` does, for
// `orthoface render DIR` and `orthoface station --camera DEV --model DIR`.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/highgui.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "app/cli.h"
#include "app/commands.h"
#include "app/station_output.h"
#include "capture/camera.h"
#include "io/atomic_file.h"
#include "reconstruct/reconstruction.h"
#include "sim/sim_camera.h"
#include "vision/face_detect.h"
#include "vision/foreground.h"

namespace orthoface::app {
namespace {

// A frontal frame this close to facing the camera ends the first prompt.
constexpr double kFrontalOkDeg = 5;
// A frame is a profile candidate when the face detector finds no face in it (dlib's detectors
// reach about 55 degrees on the sim heads) or reads it turned at least this far.
constexpr double kProfileMinDeg = 55;

Command enrol_command() {
  return {"enrol",
          "One webcam: asks the person (on stderr, and in the window with --output window) to "
          "look at the camera, then to turn to a side; picks the frame that faces the camera "
          "best (the face detector's turn estimate) and the profile frame nearest 90 degrees "
          "(the widest head silhouette once the face is turned past the detector), saves both "
          "to DIR/enrol/ (front.png, side.png, enrol.json) and reconstructs them into DIR as "
          "`orthoface reconstruct` does.",
          "orthoface enrol --camera DEV --out DIR [options]",
          {{"camera", true,
            "DEV  the camera: /dev/videoN, libcamera:ID, sim:N/front?turn=-90&frames=N or "
            "file:VIDEO[?fps=N]"},
           {"out", true, "DIR  output folder (the reconstruction; the frames in DIR/enrol/)"},
           {"size", true, "WxH  capture size (default: a file's own size, else 640x480)"},
           {"fps", true, "N  capture frame rate (default 30)"},
           {"duration", true,
            "S  give up after S seconds of the camera's frames, or of none arriving (default 60)"},
           {"hold", true,
            "S  stop once the profile has not improved for S seconds of the camera's frames "
            "(default 2; a file ends at its end)"},
           {"output", true, "none|window  where the prompts are shown besides stderr"},
           {"background", true,
            "F  the camera's empty scene (a clean plate of the capture size): the head is cut "
            "out by difference"},
           {"force", false, "model the frames even when the input check fails (exit 3 without)"}},
          0};
}

struct Settings {
  std::string camera, out, output = "none";
  int width = 640, height = 480;
  bool size_given = false, force = false;
  double fps = 30, duration_s = 60, hold_s = 2;
  cv::Mat plate;  // the clean plate, or empty
};

Settings settings_from(const Args& a) {
  Settings s;
  for (const char* flag : {"camera", "out"})
    if (!a.has(flag)) throw std::invalid_argument(std::string("enrol: --") + flag + " is required");
  s.camera = a.get("camera");
  s.out = a.get("out");
  if (a.has("size")) {
    std::tie(s.width, s.height) = to_size("size", a.get("size"), 8192);
    s.size_given = true;
  }
  if (a.has("fps")) s.fps = to_double("fps", a.get("fps"), 1, 240);
  if (a.has("duration")) s.duration_s = to_double("duration", a.get("duration"), 0.1, 1e6);
  if (a.has("hold")) s.hold_s = to_double("hold", a.get("hold"), 0.1, 600);
  s.output = a.get("output", s.output);
  if (s.output != "none" && s.output != "window")
    throw std::invalid_argument("--output: expected none or window, got '" + s.output + "'");
  s.force = a.has("force");
  // Its size is checked once the camera gives its own (a file's may not be known before).
  if (a.has("background")) s.plate = read_clean_plate(a.get("background"), "--background");
  return s;
}

// One chosen frame and what it was chosen by.
struct Pick {
  capture::Frame frame;
  double yaw_deg = std::numeric_limits<double>::quiet_NaN();  // face detector's estimate
  double score = -1;                                          // the profile measure
};

// The head's turn from the face detector's landmarks (vision::turn_index, about kTurnPerTan x
// tan yaw), degrees; NaN when no face is found.
double estimated_yaw_deg(const cv::Mat& frame) {
  const vision::FoundFace f = vision::find_face(frame);
  if (f.faces < 1 || !std::isfinite(f.turn)) return std::numeric_limits<double>::quiet_NaN();
  return std::atan(f.turn / vision::kTurnPerTan) * 180 / M_PI;
}

// How much of the head a frame shows: the head blob's area over its height squared (free of
// the head's distance). The silhouette of a head turning from frontal widens up to the full
// profile, where nose and back of the head are farthest apart, and narrows past it; 0 without a
// head blob.
double profile_score(const cv::Mat& frame, const cv::Mat& plate) {
  const cv::Mat mask = vision::head_mask(vision::foreground_probability(frame, plate));
  if (mask.empty()) return 0;
  const cv::Rect box = cv::boundingRect(mask);
  if (box.height <= 0) return 0;
  return cv::countNonZero(mask) / (double(box.height) * box.height);
}

// Saves the two frames into `dir` (a staging folder renamed into place: all or nothing).
void save_frames(const Pick& front, const Pick& side, int frames_seen, const std::string& dir) {
  namespace fs = std::filesystem;
  const std::string tmp = io::temp_path_for(dir);
  auto finite_or_null = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nullptr; };
  try {
    fs::create_directories(tmp);
    io::write_image_atomically(tmp + "/front.png", front.frame.image);
    io::write_image_atomically(tmp + "/side.png", side.frame.image);
    const nlohmann::json j = {{"front",
                               {{"sequence", front.frame.sequence},
                                {"timestamp_s", front.frame.timestamp_s},
                                {"estimated_yaw_deg", finite_or_null(front.yaw_deg)}}},
                              {"side",
                               {{"sequence", side.frame.sequence},
                                {"timestamp_s", side.frame.timestamp_s},
                                {"estimated_yaw_deg", finite_or_null(side.yaw_deg)},
                                {"profile_score", side.score}}},
                              {"frames_seen", frames_seen}};
    io::write_text_atomically(tmp + "/enrol.json", j.dump(2) + "\n");
    fs::rename(tmp, dir);
  } catch (...) {
    std::error_code ec;
    fs::remove_all(tmp, ec);
    throw;
  }
}

class Enrolment {
 public:
  explicit Enrolment(const Settings& s) : s_(s) {}
  // Runs the camera until both frames are picked (or it ends / time is up); throws naming what
  // is missing.
  void run();
  const Pick& front() const { return front_; }
  const Pick& side() const { return side_; }
  int frames_seen() const { return frames_; }

 private:
  void prompt(const std::string& text);
  void show(const cv::Mat& frame);

  Settings s_;
  std::string prompt_;
  Pick front_, side_;
  bool turning_ = false;  // the second prompt is out
  int frames_ = 0;
};

void Enrolment::prompt(const std::string& text) {
  prompt_ = text;
  std::fprintf(stderr, "enrol: %s\n", text.c_str());
}

void Enrolment::show(const cv::Mat& frame) {
  if (s_.output != "window") return;
  cv::Mat shown = frame.clone();
  cv::putText(shown, prompt_, {20, 40}, cv::FONT_HERSHEY_SIMPLEX, 1.0, cv::Scalar(0, 0, 0), 4);
  cv::putText(shown, prompt_, {20, 40}, cv::FONT_HERSHEY_SIMPLEX, 1.0, cv::Scalar(255, 255, 255),
              2);
  cv::imshow("orthoface enrol", shown);
  cv::waitKey(1);
}

void Enrolment::run() {
  sim::register_sim_cameras();
  std::unique_ptr<capture::Camera> camera = capture::open_camera(s_.camera);
  const std::vector<capture::CameraFormat> formats = camera->formats();
  if (!s_.size_given && formats.size() == 1)  // a file: its own size
    s_.width = formats[0].width, s_.height = formats[0].height;
  camera->start(capture::choose_format(formats, s_.width, s_.height, s_.fps, s_.camera));
  if (!s_.plate.empty() && (s_.plate.cols != s_.width || s_.plate.rows != s_.height))
    throw std::invalid_argument("--background: the clean plate is " +
                                std::to_string(s_.plate.cols) + "x" +
                                std::to_string(s_.plate.rows) + ", the camera gives " +
                                std::to_string(s_.width) + "x" + std::to_string(s_.height));
  prompt("look at the camera");
  // --duration and --hold count the camera's time (its frames' timestamps), so a reader slower
  // than the camera (a file played while the face detector takes longer than a frame) still
  // sees the whole turn; without frames, the wall clock since the last one.
  double first_s = NAN, last_s = NAN, improved_s = NAN;
  double last_frame_wall = capture::monotonic_now_s();
  std::string ended;
  while (true) {
    const double camera_s = std::isnan(first_s) ? 0.0 : last_s - first_s;
    if (camera_s > s_.duration_s || capture::monotonic_now_s() - last_frame_wall > s_.duration_s) {
      ended = "time is up after " + std::to_string(int(s_.duration_s)) + " s";
      break;
    }
    if (side_.score > 0 && last_s - improved_s > s_.hold_s) break;
    capture::FrameResult r = camera->next_frame(1.0);
    if (r.status == capture::FrameStatus::Disconnected) {
      ended = r.message;
      break;
    }
    if (r.status != capture::FrameStatus::Ok) continue;
    last_frame_wall = capture::monotonic_now_s();
    last_s = r.frame.timestamp_s;
    if (std::isnan(first_s)) first_s = last_s;
    ++frames_;
    const double yaw = estimated_yaw_deg(r.frame.image);
    if (std::isfinite(yaw) && !(std::abs(yaw) >= std::abs(front_.yaw_deg))) {
      front_.frame = r.frame;
      front_.yaw_deg = yaw;
    }
    if (!turning_ && std::abs(front_.yaw_deg) <= kFrontalOkDeg) {
      turning_ = true;
      prompt("turn to your side (left or right) and hold");
    }
    if (turning_ && !(std::abs(yaw) < kProfileMinDeg)) {
      const double score = profile_score(r.frame.image, s_.plate);
      if (score > side_.score) {
        side_ = {r.frame, yaw, score};
        improved_s = r.frame.timestamp_s;
      }
    }
    show(r.frame.image);
  }
  camera->stop();
  const std::string why = ended.empty() ? "" : " (" + ended + ")";
  if (front_.frame.image.empty())
    throw std::runtime_error("enrol: no face found in " + std::to_string(frames_) + " frames of " +
                             s_.camera + why + ": look at the camera");
  if (side_.score <= 0) {
    char best[64];
    std::snprintf(best, sizeof(best), "%.1f", front_.yaw_deg);
    throw std::runtime_error("enrol: no profile frame in " + std::to_string(frames_) +
                             " frames of " + s_.camera + why +
                             ": turn to a side until the face is seen in profile (the best "
                             "frontal frame was turned " +
                             best + " deg)");
  }
}

}  // namespace

int run_enrol(int argc, char** argv) {
  const Command command = enrol_command();
  const Args args = parse_args(command, argc, argv);
  if (args.help) {
    print_help(command);
    return 0;
  }
  const Settings s = settings_from(args);
  if (s.output == "window") require_display("--output window");
  const std::string enrol_dir = s.out + "/enrol";
  if (std::filesystem::exists(enrol_dir))
    throw std::runtime_error("enrol: " + enrol_dir + " already exists (choose a new --out)");
  const bool out_existed = std::filesystem::exists(s.out);
  prepare_output_dir(s.out);
  Enrolment enrolment(s);
  try {
    enrolment.run();
  } catch (...) {
    // Nothing was saved: a folder made for it goes again (remove() leaves a non-empty one).
    std::error_code ec;
    if (!out_existed) std::filesystem::remove(s.out, ec);
    throw;
  }
  // The frames are kept before anything is computed from them: a refused or failed model
  // leaves them for another try (`orthoface reconstruct --front ... --side ...`).
  save_frames(enrolment.front(), enrolment.side(), enrolment.frames_seen(), enrol_dir);
  std::printf("frames saved: %s (front: frame %llu, estimated yaw %.1f deg; side: frame %llu)\n",
              enrol_dir.c_str(), static_cast<unsigned long long>(enrolment.front().frame.sequence),
              enrolment.front().yaw_deg,
              static_cast<unsigned long long>(enrolment.side().frame.sequence));
  std::fflush(stdout);
  reconstruct::ReconstructOptions ro;
  ro.force = s.force;
  ro.observe.background_front = s.plate;  // one camera: the same empty scene for both frames
  ro.observe.background_side = s.plate;
  try {
    const reconstruct::Reconstruction r =
        reconstruct::from_photos(enrolment.front().frame.image, enrolment.side().frame.image, ro);
    reconstruct::write_reconstruction(r, s.out);
  } catch (const reconstruct::InputRefused& e) {
    throw reconstruct::InputRefused(e.check(),
                                    e.problem() + "; the frames are kept in " + enrol_dir);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string(e.what()) + " (the frames are kept in " + enrol_dir + ")");
  }
  std::printf("model written: %s\n", s.out.c_str());
  return 0;
}

}  // namespace orthoface::app
