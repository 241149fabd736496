#pragma once

#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace orthoface::app {

// The station's small HTTP server (POSIX sockets): a page with the live images (polled JPEGs),
// /NAME.jpg and /NAME.mjpg (multipart stream) for each published image, /status (JSON), /view
// (GET reads, POST ?yaw=&pitch= sets the output's view), and POST /capture, /refit which queue an
// action for the station loop. One thread per connection, joined once it has finished.
//
// Made for a LAN and a browser on it: at most kMaxConnections connections are served at once
// (more get 503 straight away) and kMaxStreams of them MJPEG streams; a request must arrive whole
// within 2 s and 8 KiB (408 / 431); a client that stops reading is dropped after 1 s; the Host
// header must name this machine (an IP literal, localhost or its host name: a web page cannot read
// the cameras through DNS rebinding, 403 otherwise); state changes are POST only (405) and refused
// from another Origin (403); other methods get 405, a malformed request 400. The destructor
// returns within about a second whatever the clients do. cpp-httplib 0.11 (Debian 12) does not
// give the last three: its read timeout is per read (a client sending a byte a second holds a
// worker for hours) and on stop its pool serves every queued connection to the end.
class StationHttp {
 public:
  static constexpr size_t kMaxConnections = 32;
  static constexpr size_t kMaxStreams = 8;

  // Listens on bind_address:port. Throws std::runtime_error naming the port when it is in use or
  // cannot be bound; std::invalid_argument for a port outside 1..65535.
  StationHttp(const std::string& bind_address, int port);
  ~StationHttp();  // stops the server and joins its threads
  StationHttp(const StationHttp&) = delete;
  StationHttp& operator=(const StationHttp&) = delete;

  // Latest image under `name` ("front", "side", "view"); JPEG-encoded only when a client asks,
  // so an unwatched station spends nothing on it.
  void publish(const std::string& name, const cv::Mat& bgr);
  void set_status(const std::string& json);
  std::vector<std::string> take_actions();  // "capture" / "refit" requested since the last call
  int port() const { return port_; }
  // The view the output shows (degrees), set by the station at start and by GET /view?yaw=&pitch=
  // (the page's sliders).
  void set_view(double yaw_deg, double pitch_deg);
  std::pair<double, double> view();
  // Connection threads held (serving or finished and not yet joined): finished ones are joined
  // as new connections come, so this stays near the number of open connections.
  size_t worker_threads();

 private:
  struct Request;
  void accept_loop();
  void serve(int fd);
  void route(int fd, const Request& request);
  void stream(int fd, const std::string& name, bool head);
  void serve_view(int fd, const std::string& query, bool head);

  int port_ = 0;
  int listen_fd_ = -1;
  bool stopping_ = false;
  std::mutex m_;
  std::condition_variable cv_;
  struct Slot {
    cv::Mat image;
    unsigned long version = 0;
    std::vector<unsigned char> jpeg;  // of jpeg_version
    unsigned long jpeg_version = 0;
  };
  std::vector<unsigned char> jpeg_of(const std::string& name,
                                     unsigned long* version);  // "" if none
  std::map<std::string, Slot> images_;
  std::string status_ = "{}";
  double view_yaw_ = 0, view_pitch_ = 0;
  std::vector<std::string> actions_;
  size_t streams_ = 0;  // MJPEG streams being served, under m_
  struct Worker {
    std::thread thread;
    std::shared_ptr<int> fd;  // the connection, -1 once closed (under m_)
  };
  std::vector<Worker> workers_;  // under m_; finished ones joined by accept_loop
  std::thread acceptor_;
};

}  // namespace orthoface::app
