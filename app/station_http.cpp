#include "app/station_http.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

namespace orthoface::app {
namespace {

const char* kPage = R"html(<!doctype html>
<html><head><meta charset="utf-8"><title>orthoface station</title>
<style>body{font-family:sans-serif;background:#222;color:#eee;margin:12px}
figure{display:inline-block;margin:6px}img{width:400px;border:1px solid #555}
button{font-size:16px;margin:4px}</style></head><body>
<h2>orthoface station</h2>
<figure><img id="front" src="/front.jpg"><figcaption>front camera</figcaption></figure>
<figure><img id="side" src="/side.jpg"><figcaption>side camera</figcaption></figure>
<figure><img id="view" src="/view.jpg"><figcaption>rotated view</figcaption></figure>
<div>yaw <input id="yaw" type="range" min="-90" max="90" step="1"> <span id="yawv"></span>
pitch <input id="pitch" type="range" min="-60" max="60" step="1"> <span id="pitchv"></span></div>
<div><button onclick="fetch('/capture')">take pair</button>
<button onclick="fetch('/refit')">refit model</button>
streams: <a href="/front.mjpg">front</a> <a href="/side.mjpg">side</a> <a href="/view.mjpg">view</a></div>
<pre id="status"></pre>
<script>
function poll(id){const i=document.getElementById(id);const n=new Image();
 n.onload=()=>{i.src=n.src;setTimeout(()=>poll(id),60)};n.onerror=()=>setTimeout(()=>poll(id),500);
 n.src='/'+id+'.jpg?t='+Date.now();}
['front','side','view'].forEach(poll);
function shown(v){yaw.value=v.yaw;pitch.value=v.pitch;yawv.textContent=v.yaw;pitchv.textContent=v.pitch}
fetch('/view').then(r=>r.json()).then(shown);
[yaw,pitch].forEach(s=>s.oninput=()=>fetch('/view?yaw='+yaw.value+'&pitch='+pitch.value)
 .then(r=>r.json()).then(shown));
setInterval(()=>fetch('/status').then(r=>r.text()).then(t=>{document.getElementById('status').textContent=t}),500);
</script></body></html>
)html";

bool send_all(int fd, const void* data, size_t n) {
  const char* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t k = ::send(fd, p, n, MSG_NOSIGNAL);
    if (k <= 0) {
      if (k < 0 && errno == EINTR) continue;
      return false;
    }
    p += k;
    n -= size_t(k);
  }
  return true;
}

bool send_text(int fd, const std::string& s) { return send_all(fd, s.data(), s.size()); }

void respond(int fd, const std::string& status, const std::string& type, const std::string& body) {
  send_text(fd, "HTTP/1.1 " + status + "\r\nContent-Type: " + type +
                    "\r\nCache-Control: no-store\r\nConnection: close\r\nContent-Length: " +
                    std::to_string(body.size()) + "\r\n\r\n" + body);
}

// The request path of "GET /x?y HTTP/1.1", without the query; "" if unreadable.
// The request's target (path and query).
std::string read_target(int fd) {
  std::string req;
  char buf[1024];
  while (req.find("\r\n\r\n") == std::string::npos && req.size() < 8192) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 2000) <= 0) return "";
    const ssize_t k = ::recv(fd, buf, sizeof(buf), 0);
    if (k <= 0) return "";
    req.append(buf, size_t(k));
  }
  const size_t a = req.find(' '), b = req.find(' ', a + 1);
  if (a == std::string::npos || b == std::string::npos) return "";
  return req.substr(a + 1, b - a - 1);
}

// `text` as a number in [lo, hi], else nullopt.
std::optional<double> number_in(const std::string& text, double lo, double hi) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v) || v < lo || v > hi)
    return std::nullopt;
  return v;
}

}  // namespace

StationHttp::StationHttp(const std::string& bind_address, int port) : port_(port) {
  if (port < 1 || port > 65535)
    throw std::invalid_argument("http port " + std::to_string(port) + " is outside 1..65535");
  listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (listen_fd_ < 0)
    throw std::runtime_error("http: cannot create a socket: " + std::string(std::strerror(errno)));
  const int one = 1;
  setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(uint16_t(port));
  if (inet_pton(AF_INET, bind_address.c_str(), &addr.sin_addr) != 1) {
    ::close(listen_fd_);
    throw std::invalid_argument("http: bad bind address '" + bind_address + "'");
  }
  if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0 ||
      ::listen(listen_fd_, 16) != 0) {
    const int e = errno;
    ::close(listen_fd_);
    throw std::runtime_error("http: port " + std::to_string(port) + " on " + bind_address +
                             (e == EADDRINUSE ? std::string(" is already in use")
                                              : ": " + std::string(std::strerror(e))));
  }
  acceptor_ = std::thread([this] { accept_loop(); });
}

StationHttp::~StationHttp() {
  {
    std::lock_guard<std::mutex> lock(m_);
    stopping_ = true;
  }
  cv_.notify_all();
  if (acceptor_.joinable()) acceptor_.join();
  for (auto& w : workers_) w.thread.join();
  ::close(listen_fd_);
}

void StationHttp::accept_loop() {
  for (;;) {
    {
      std::lock_guard<std::mutex> lock(m_);
      if (stopping_) return;
    }
    pollfd p{listen_fd_, POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (fd < 0) continue;
    std::vector<std::thread> finished;
    {
      std::lock_guard<std::mutex> lock(m_);
      for (auto it = workers_.begin(); it != workers_.end();)
        if (it->done->load()) {
          finished.push_back(std::move(it->thread));
          it = workers_.erase(it);
        } else {
          ++it;
        }
      auto done = std::make_shared<std::atomic<bool>>(false);
      workers_.push_back({std::thread([this, fd, done] {
                            serve(fd);
                            ::close(fd);
                            done->store(true);
                          }),
                          done});
    }
    for (auto& t : finished) t.join();  // already returned: joins at once
  }
}

void StationHttp::serve(int fd) {
  const std::string target = read_target(fd);
  if (target.empty()) return;
  const size_t q = target.find('?');
  const std::string path = target.substr(0, q);
  const std::string query = q == std::string::npos ? "" : target.substr(q + 1);
  if (path == "/view") return serve_view(fd, query);
  if (path == "/" || path == "/index.html") return respond(fd, "200 OK", "text/html", kPage);
  if (path == "/status") {
    std::lock_guard<std::mutex> lock(m_);
    return respond(fd, "200 OK", "application/json", status_);
  }
  if (path == "/capture" || path == "/refit") {
    {
      std::lock_guard<std::mutex> lock(m_);
      actions_.push_back(path.substr(1));
    }
    return respond(fd, "202 Accepted", "application/json",
                   "{\"queued\": \"" + path.substr(1) + "\"}");
  }
  const size_t dot = path.rfind('.');
  const std::string name = dot == std::string::npos ? "" : path.substr(1, dot - 1);
  const std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  if (ext == ".mjpg") return stream(fd, name);
  if (ext == ".jpg") {
    const std::vector<unsigned char> jpeg = jpeg_of(name, nullptr);
    if (jpeg.empty()) return respond(fd, "404 Not Found", "text/plain", "no image yet\n");
    return respond(fd, "200 OK", "image/jpeg", std::string(jpeg.begin(), jpeg.end()));
  }
  respond(fd, "404 Not Found", "text/plain", "not found\n");
}

void StationHttp::stream(int fd, const std::string& name) {
  if (!send_text(fd,
                 "HTTP/1.1 200 OK\r\nContent-Type: multipart/x-mixed-replace; boundary=frame\r\n"
                 "Cache-Control: no-store\r\nConnection: close\r\n\r\n"))
    return;
  unsigned long seen = 0;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(m_);
      cv_.wait_for(lock, std::chrono::seconds(1), [&] {
        auto it = images_.find(name);
        return stopping_ || (it != images_.end() && it->second.version != seen);
      });
      if (stopping_) return;
    }
    const std::vector<unsigned char> jpeg = jpeg_of(name, &seen);
    if (jpeg.empty()) continue;
    const std::string head =
        "--frame\r\nContent-Type: image/jpeg\r\nContent-Length: " + std::to_string(jpeg.size()) +
        "\r\n\r\n";
    if (!send_text(fd, head) || !send_all(fd, jpeg.data(), jpeg.size()) || !send_text(fd, "\r\n"))
      return;
  }
}

void StationHttp::publish(const std::string& name, const cv::Mat& bgr) {
  {
    std::lock_guard<std::mutex> lock(m_);
    Slot& slot = images_[name];
    slot.image = bgr;  // shares the pixels; the station never writes into a published image
    ++slot.version;
  }
  cv_.notify_all();
}

std::vector<unsigned char> StationHttp::jpeg_of(const std::string& name, unsigned long* version) {
  cv::Mat image;
  unsigned long v = 0;
  {
    std::lock_guard<std::mutex> lock(m_);
    auto it = images_.find(name);
    if (it == images_.end()) return {};
    if (it->second.jpeg_version == it->second.version) {
      if (version) *version = it->second.version;
      return it->second.jpeg;
    }
    image = it->second.image;
    v = it->second.version;
  }
  std::vector<unsigned char> jpeg;
  cv::imencode(".jpg", image, jpeg, {cv::IMWRITE_JPEG_QUALITY, 80});
  std::lock_guard<std::mutex> lock(m_);
  Slot& slot = images_[name];
  if (v > slot.jpeg_version) slot.jpeg = jpeg, slot.jpeg_version = v;
  if (version) *version = v;
  return jpeg;
}

void StationHttp::set_status(const std::string& json) {
  std::lock_guard<std::mutex> lock(m_);
  status_ = json;
}

// GET /view?yaw=DEG&pitch=DEG: either or both set the view (yaw -90..90, pitch -60..60); 200
// with the values in force, 400 naming the first bad parameter (nothing changes then).
void StationHttp::serve_view(int fd, const std::string& query) {
  double yaw = 0, pitch = 0;
  {
    std::lock_guard<std::mutex> lock(m_);
    yaw = view_yaw_, pitch = view_pitch_;
  }
  std::stringstream ss(query);
  for (std::string item; std::getline(ss, item, '&');) {
    if (item.empty()) continue;
    const size_t eq = item.find('=');
    const std::string key = item.substr(0, eq),
                      value = eq == std::string::npos ? "" : item.substr(eq + 1);
    const bool is_yaw = key == "yaw";
    if (!is_yaw && key != "pitch")
      return respond(fd, "400 Bad Request", "application/json",
                     "{\"error\": \"unknown parameter '" + key + "': expected yaw, pitch\"}");
    const auto v = number_in(value, is_yaw ? -90 : -60, is_yaw ? 90 : 60);
    if (!v)
      return respond(fd, "400 Bad Request", "application/json",
                     "{\"error\": \"" + key + " must be a number in " +
                         (is_yaw ? "-90..90" : "-60..60") + " degrees\"}");
    (is_yaw ? yaw : pitch) = *v;
  }
  set_view(yaw, pitch);
  char json[96];
  std::snprintf(json, sizeof(json), "{\"yaw\": %.2f, \"pitch\": %.2f}", yaw, pitch);
  respond(fd, "200 OK", "application/json", json);
}

void StationHttp::set_view(double yaw_deg, double pitch_deg) {
  std::lock_guard<std::mutex> lock(m_);
  view_yaw_ = yaw_deg, view_pitch_ = pitch_deg;
}

std::pair<double, double> StationHttp::view() {
  std::lock_guard<std::mutex> lock(m_);
  return {view_yaw_, view_pitch_};
}

size_t StationHttp::worker_threads() {
  std::lock_guard<std::mutex> lock(m_);
  return workers_.size();
}

std::vector<std::string> StationHttp::take_actions() {
  std::lock_guard<std::mutex> lock(m_);
  std::vector<std::string> out;
  out.swap(actions_);
  return out;
}

}  // namespace orthoface::app
