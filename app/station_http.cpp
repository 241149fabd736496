#include "app/station_http.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
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

constexpr size_t kMaxRequestBytes = 8192;
constexpr auto kRequestDeadline = std::chrono::seconds(2);
constexpr int kSendTimeoutMs = 1000;

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
<div><button onclick="fetch('/capture',{method:'POST'})">take pair</button>
<button onclick="fetch('/refit',{method:'POST'})">refit model</button>
streams: <a href="/front.mjpg">front</a> <a href="/side.mjpg">side</a> <a href="/view.mjpg">view</a></div>
<pre id="status"></pre>
<script>
function poll(id){const i=document.getElementById(id);const n=new Image();
 n.onload=()=>{i.src=n.src;setTimeout(()=>poll(id),60)};n.onerror=()=>setTimeout(()=>poll(id),500);
 n.src='/'+id+'.jpg?t='+Date.now();}
['front','side','view'].forEach(poll);
function shown(v){yaw.value=v.yaw;pitch.value=v.pitch;yawv.textContent=v.yaw;pitchv.textContent=v.pitch}
fetch('/view').then(r=>r.json()).then(shown);
[yaw,pitch].forEach(s=>s.oninput=()=>fetch('/view?yaw='+yaw.value+'&pitch='+pitch.value,{method:'POST'})
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
      return false;  // closed, shut down, or no progress within the send timeout
    }
    p += k;
    n -= size_t(k);
  }
  return true;
}

bool send_text(int fd, const std::string& s) { return send_all(fd, s.data(), s.size()); }

// A whole response; HEAD gets the headers alone. `extra` adds header lines ("Allow: POST\r\n").
void respond(int fd, const std::string& status, const std::string& type, const std::string& body,
             bool head = false, const std::string& extra = "") {
  send_text(fd, "HTTP/1.1 " + status + "\r\nContent-Type: " + type +
                    "\r\nCache-Control: no-store\r\nConnection: close\r\nContent-Length: " +
                    std::to_string(body.size()) + "\r\n" + extra + "\r\n" + (head ? "" : body));
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string trimmed(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t");
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

// `text` as a number in [lo, hi], else nullopt.
std::optional<double> number_in(const std::string& text, double lo, double hi) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v) || v < lo || v > hi)
    return std::nullopt;
  return v;
}

// The host part of a Host header value ("example.org:8080" -> "example.org", "[::1]:80" ->
// "[::1]"), lower case.
std::string host_name(const std::string& host) {
  if (!host.empty() && host[0] == '[') return lower(host.substr(0, host.find(']') + 1));
  return lower(host.substr(0, host.rfind(':')));
}

// A Host naming this machine: an IP literal, localhost or this machine's name. A name anyone
// else controls is what DNS rebinding needs, so none is accepted.
bool host_allowed(const std::string& host) {
  const std::string name = host_name(host);
  if (name.empty()) return false;
  if (name.front() == '[' && name.back() == ']') return true;
  in_addr a{};
  if (inet_pton(AF_INET, name.c_str(), &a) == 1) return true;
  if (name == "localhost") return true;
  char self[256] = {};
  if (::gethostname(self, sizeof(self) - 1) != 0) return false;
  const std::string me = lower(self);
  return name == me || name == me + ".local";
}

}  // namespace

struct StationHttp::Request {
  std::string method, target;
  std::map<std::string, std::string> headers;  // names in lower case
  std::string header(const std::string& name) const {
    const auto it = headers.find(name);
    return it == headers.end() ? "" : it->second;
  }
};

namespace {

enum class ReadStatus { Ok, Closed, Malformed, TooLarge, Late };

// Reads the request head (request line and headers) within kRequestDeadline and
// kMaxRequestBytes; the body, if any, is never needed.
template <class Request>
ReadStatus read_request(int fd, Request& r) {
  const auto deadline = std::chrono::steady_clock::now() + kRequestDeadline;
  std::string req;
  char buf[1024];
  size_t end;
  while ((end = req.find("\r\n\r\n")) == std::string::npos) {
    if (req.size() > kMaxRequestBytes) return ReadStatus::TooLarge;
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return req.empty() ? ReadStatus::Closed : ReadStatus::Late;
    pollfd p{fd, POLLIN, 0};
    const int n = ::poll(&p, 1, int(left.count()));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return req.empty() ? ReadStatus::Closed : ReadStatus::Late;
    const ssize_t k = ::recv(fd, buf, sizeof(buf), 0);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) return ReadStatus::Closed;
    req.append(buf, size_t(k));
  }
  if (end > kMaxRequestBytes) return ReadStatus::TooLarge;
  std::istringstream lines(req.substr(0, end + 2));
  std::string line;
  std::getline(lines, line);
  if (line.empty() || line.back() != '\r') return ReadStatus::Malformed;
  line.pop_back();
  const size_t a = line.find(' '), b = line.find(' ', a + 1);
  if (a == 0 || a == std::string::npos || b == std::string::npos) return ReadStatus::Malformed;
  r.method = line.substr(0, a);
  r.target = line.substr(a + 1, b - a - 1);
  const std::string version = line.substr(b + 1);
  if (!std::all_of(r.method.begin(), r.method.end(), [](char c) { return c >= 'A' && c <= 'Z'; }) ||
      r.target.empty() || r.target[0] != '/' || version.rfind("HTTP/1.", 0) != 0)
    return ReadStatus::Malformed;
  while (std::getline(lines, line)) {
    if (line.empty() || line.back() != '\r') return ReadStatus::Malformed;
    line.pop_back();
    const size_t colon = line.find(':');
    if (colon == 0 || colon == std::string::npos) return ReadStatus::Malformed;
    r.headers[lower(line.substr(0, colon))] = trimmed(line.substr(colon + 1));
  }
  return ReadStatus::Ok;
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
      ::listen(listen_fd_, 64) != 0) {
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
    // Whatever a connection waits on (a slow request, a client that stopped reading) returns.
    for (auto& w : workers_)
      if (*w.fd >= 0) ::shutdown(*w.fd, SHUT_RDWR);
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
    const timeval send_timeout{kSendTimeoutMs / 1000, (kSendTimeoutMs % 1000) * 1000};
    setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &send_timeout, sizeof(send_timeout));
    std::vector<std::thread> finished;
    bool busy = false;
    {
      std::lock_guard<std::mutex> lock(m_);
      for (auto it = workers_.begin(); it != workers_.end();)
        if (*it->fd < 0) {
          finished.push_back(std::move(it->thread));
          it = workers_.erase(it);
        } else {
          ++it;
        }
      if (stopping_) {
        ::close(fd);
      } else if (workers_.size() >= kMaxConnections) {
        busy = true;
      } else {
        auto slot = std::make_shared<int>(fd);
        workers_.push_back({std::thread([this, slot] {
                              serve(*slot);
                              std::lock_guard<std::mutex> done(m_);
                              ::close(*slot);
                              *slot = -1;
                            }),
                            slot});
      }
    }
    if (busy) {  // answered from here, never waiting on the client
      const std::string r =
          "HTTP/1.1 503 Service Unavailable\r\nConnection: close\r\nRetry-After: 1\r\n"
          "Content-Length: 0\r\n\r\n";
      ::send(fd, r.data(), r.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
      ::close(fd);
    }
    for (auto& t : finished) t.join();  // already returned: joins at once
  }
}

void StationHttp::serve(int fd) {
  try {
    Request r;
    switch (read_request(fd, r)) {
      case ReadStatus::Ok:
        return route(fd, r);
      case ReadStatus::Closed:
        return;
      case ReadStatus::Malformed:
        return respond(fd, "400 Bad Request", "text/plain", "malformed request\n");
      case ReadStatus::TooLarge:
        return respond(fd, "431 Request Header Fields Too Large", "text/plain",
                       "the request head is over 8 KiB\n");
      case ReadStatus::Late:
        return respond(fd, "408 Request Timeout", "text/plain",
                       "the request did not arrive within 2 s\n");
    }
  } catch (const std::exception&) {
    // A connection's failure (an image that cannot be encoded, memory) ends that connection only.
  }
}

void StationHttp::route(int fd, const Request& r) {
  const std::string host = r.header("host");
  if (host.empty()) return respond(fd, "400 Bad Request", "text/plain", "no Host header\n");
  if (!host_allowed(host))
    return respond(fd, "403 Forbidden", "text/plain",
                   "this station answers to its address, localhost or its host name\n");
  const size_t q = r.target.find('?');
  const std::string path = r.target.substr(0, q);
  const std::string query = q == std::string::npos ? "" : r.target.substr(q + 1);
  const bool head = r.method == "HEAD";
  // What changes the station: POST only, and only from a page this station served (a browser
  // sends Origin with every cross-site POST; curl and scripts send none).
  const bool changes =
      path == "/capture" || path == "/refit" || (path == "/view" && !query.empty());
  if (changes) {
    if (r.method != "POST")
      return respond(fd, "405 Method Not Allowed", "text/plain", path + " takes POST\n", head,
                     "Allow: POST\r\n");
    const std::string origin = r.header("origin");
    if ((!origin.empty() && lower(origin) != "http://" + lower(host)) ||
        r.header("sec-fetch-site") == "cross-site")
      return respond(fd, "403 Forbidden", "text/plain", "a request from another site\n");
  } else if (r.method != "GET" && !head) {
    return respond(fd, "405 Method Not Allowed", "text/plain", path + " takes GET or HEAD\n", false,
                   "Allow: GET, HEAD\r\n");
  }
  if (path == "/view") return serve_view(fd, query, head);
  if (path == "/" || path == "/index.html") return respond(fd, "200 OK", "text/html", kPage, head);
  if (path == "/status") {
    std::string status;
    {
      std::lock_guard<std::mutex> lock(m_);
      status = status_;
    }
    return respond(fd, "200 OK", "application/json", status, head);
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
  if (ext == ".mjpg") return stream(fd, name, head);
  if (ext == ".jpg") {
    const std::vector<unsigned char> jpeg = jpeg_of(name, nullptr);
    if (jpeg.empty()) return respond(fd, "404 Not Found", "text/plain", "no image yet\n", head);
    return respond(fd, "200 OK", "image/jpeg", std::string(jpeg.begin(), jpeg.end()), head);
  }
  respond(fd, "404 Not Found", "text/plain", "not found\n", head);
}

void StationHttp::stream(int fd, const std::string& name, bool head) {
  {
    std::lock_guard<std::mutex> lock(m_);
    if (streams_ >= kMaxStreams)
      return respond(fd, "503 Service Unavailable", "text/plain",
                     "too many streams: " + std::to_string(kMaxStreams) + " are open\n", head,
                     "Retry-After: 5\r\n");
    ++streams_;
  }
  struct Release {
    StationHttp* http;
    ~Release() {
      std::lock_guard<std::mutex> lock(http->m_);
      --http->streams_;
    }
  } release{this};
  if (!send_text(fd,
                 "HTTP/1.1 200 OK\r\nContent-Type: multipart/x-mixed-replace; boundary=frame\r\n"
                 "Cache-Control: no-store\r\nConnection: close\r\n\r\n") ||
      head)
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
    const std::string part_head =
        "--frame\r\nContent-Type: image/jpeg\r\nContent-Length: " + std::to_string(jpeg.size()) +
        "\r\n\r\n";
    if (!send_text(fd, part_head) || !send_all(fd, jpeg.data(), jpeg.size()) ||
        !send_text(fd, "\r\n"))
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

// GET /view: the view in force. POST /view?yaw=DEG&pitch=DEG: either or both set it (yaw
// -90..90, pitch -60..60); 200 with the values in force, 400 naming the first bad parameter
// (nothing changes then).
void StationHttp::serve_view(int fd, const std::string& query, bool head) {
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
  respond(fd, "200 OK", "application/json", json, head);
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
