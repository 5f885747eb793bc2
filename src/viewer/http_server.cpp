#include "viewer/http_server.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <system_error>
#include <thread>
#include <vector>

#include "core/error.h"
#include "core/log.h"

namespace glint::viewer {
namespace {

constexpr std::size_t kMaxRequestHead = 16 * 1024;
constexpr std::size_t kSendChunk = 64 * 1024;

// Sends all of `data`; false when the peer is gone or stalls past the socket's send timeout.
// MSG_NOSIGNAL: a closed peer is an error here, not a SIGPIPE for the whole program.
bool send_all(int connection, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t sent = ::send(connection, data, size, MSG_NOSIGNAL);
    if (sent < 0 && errno == EINTR) continue;
    if (sent <= 0) return false;
    data += sent;
    size -= std::size_t(sent);
  }
  return true;
}

void send_status(int connection, int status, const char* reason, const char* extra_header = "") {
  const std::string body = std::to_string(status) + " " + reason + "\n";
  const std::string response = "HTTP/1.1 " + std::to_string(status) + " " + reason +
                               "\r\nContent-Type: text/plain; charset=utf-8\r\nContent-Length: " +
                               std::to_string(body.size()) + "\r\n" + extra_header +
                               "Connection: close\r\n\r\n" + body;
  send_all(connection, response.data(), response.size());
}

std::string address_of(const ServerParams& params) {
  return params.host + ":" + std::to_string(params.port);
}

}  // namespace

HttpServer::HttpServer(const StaticSite& site, ServerParams params)
    : site_(site), params_(std::move(params)) {
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(std::uint16_t(params_.port));
  if (params_.port < 0 || params_.port > 65535 ||
      ::inet_pton(AF_INET, params_.host.c_str(), &address.sin_addr) != 1)
    throw Error(address_of(params_), "", "not an IPv4 address and port");
  listener_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (listener_ < 0) throw Error(address_of(params_), "", std::strerror(errno));
  // Lets a restarted viewer take its port back from connections still in TIME_WAIT; a port
  // another program listens on stays refused (EADDRINUSE).
  const int yes = 1;
  ::setsockopt(listener_, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  if (::bind(listener_, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
      ::listen(listener_, 64) != 0) {
    const int failure = errno;
    ::close(listener_);
    throw Error(address_of(params_), "",
                failure == EADDRINUSE ? "port in use (choose another with --port)"
                                      : std::strerror(failure));
  }
  socklen_t length = sizeof address;
  ::getsockname(listener_, reinterpret_cast<sockaddr*>(&address), &length);
  port_ = ntohs(address.sin_port);
  if (::pipe2(wake_pipe_, O_CLOEXEC | O_NONBLOCK) != 0) {
    ::close(listener_);
    throw Error(address_of(params_), "", std::strerror(errno));
  }
}

HttpServer::~HttpServer() {
  ::close(listener_);
  ::close(wake_pipe_[0]);
  ::close(wake_pipe_[1]);
}

std::string HttpServer::url() const {
  return "http://" + params_.host + ":" + std::to_string(port_) + "/";
}

void HttpServer::stop() noexcept {
  const char byte = 1;
  [[maybe_unused]] const ssize_t written = ::write(wake_pipe_[1], &byte, 1);
}

void HttpServer::serve() {
  std::array<pollfd, 2> watched{{{listener_, POLLIN, 0}, {wake_pipe_[0], POLLIN, 0}}};
  while (true) {
    if (::poll(watched.data(), watched.size(), -1) < 0) {
      if (errno == EINTR) continue;
      throw Error(url(), "", std::string("poll: ") + std::strerror(errno));
    }
    if (watched[1].revents) break;
    if (!(watched[0].revents & POLLIN)) continue;
    const int connection = ::accept4(listener_, nullptr, nullptr, SOCK_CLOEXEC);
    if (connection < 0) continue;  // the client gave up, or out of descriptors for a moment
    const timeval timeout{params_.idle_timeout_s, 0};
    ::setsockopt(connection, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
    ::setsockopt(connection, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof timeout);
    {
      std::lock_guard lock(mutex_);
      if (int(open_.size()) >= params_.max_connections) {
        send_status(connection, 503, "Service Unavailable");
        ::close(connection);
        ++requests_;
        continue;
      }
      open_.insert(connection);
    }
    try {
      std::thread([this, connection] { handle(connection); }).detach();
    } catch (const std::system_error&) {  // out of threads: answered like a full server
      send_status(connection, 503, "Service Unavailable");
      std::lock_guard lock(mutex_);
      open_.erase(connection);
      ::close(connection);
    }
  }
  // Wake the connections still being served (a blocked recv or send returns) and wait for them.
  std::unique_lock lock(mutex_);
  for (const int connection : open_) ::shutdown(connection, SHUT_RDWR);
  finished_.wait(lock, [this] { return open_.empty(); });
  // Drain the wake-up byte so that serve() can run again.
  char byte;
  while (::read(wake_pipe_[0], &byte, 1) > 0) {
  }
}

void HttpServer::handle(int connection) {
  try {
    answer(connection);
  } catch (const std::exception& failure) {
    log().warn("viewer server: {}", failure.what());
  }
  // A lingering close: closing with unread request bytes (an over-long head) would reset the
  // connection and the client could lose the response, so what is left is read first, for at
  // most a second and 1 MiB.
  ::shutdown(connection, SHUT_WR);
  const timeval linger{1, 0};
  ::setsockopt(connection, SOL_SOCKET, SO_RCVTIMEO, &linger, sizeof linger);
  char discard[4096];
  for (std::size_t drained = 0; drained < (1u << 20);) {
    const ssize_t got = ::recv(connection, discard, sizeof discard, 0);
    if (got <= 0) break;
    drained += std::size_t(got);
  }
  // Closed and notified under the lock: serve() cannot return (and the server be destroyed)
  // before this thread is done with it.
  std::lock_guard lock(mutex_);
  open_.erase(connection);
  ::close(connection);
  finished_.notify_all();
}

void HttpServer::answer(int connection) {
  std::string head;
  std::vector<char> buffer(kSendChunk);
  std::size_t head_end;
  while ((head_end = head.find("\r\n\r\n")) == std::string::npos || head_end > kMaxRequestHead) {
    if (head.size() > kMaxRequestHead) {
      ++requests_;
      send_status(connection, 431, "Request Header Fields Too Large");
      return;
    }
    const ssize_t received = ::recv(connection, buffer.data(), buffer.size(), 0);
    if (received < 0 && errno == EINTR) continue;
    if (received <= 0) return;  // closed, idle past the timeout, or shut down by serve()
    head.append(buffer.data(), std::size_t(received));
  }
  ++requests_;
  // Request line: METHOD SP TARGET SP VERSION.
  const std::string line = head.substr(0, head.find("\r\n"));
  const std::size_t first = line.find(' '), second = line.find(' ', first + 1);
  if (first == std::string::npos || second == std::string::npos) {
    send_status(connection, 400, "Bad Request");
    return;
  }
  const std::string method = line.substr(0, first);
  const std::string target = line.substr(first + 1, second - first - 1);
  if (method != "GET" && method != "HEAD") {
    send_status(connection, 405, "Method Not Allowed", "Allow: GET, HEAD\r\n");
    log().debug("viewer server: {} {} 405", method, target);
    return;
  }
  const std::optional<std::filesystem::path> file = site_.resolve(target);
  const int descriptor = file ? ::open(file->c_str(), O_RDONLY | O_CLOEXEC) : -1;
  struct stat status {};
  if (descriptor < 0 || ::fstat(descriptor, &status) != 0) {
    if (descriptor >= 0) ::close(descriptor);
    send_status(connection, 404, "Not Found");
    log().debug("viewer server: {} {} 404", method, target);
    return;
  }
  const std::string response_head =
      "HTTP/1.1 200 OK\r\nContent-Type: " + content_type(*file) +
      "\r\nContent-Length: " + std::to_string(status.st_size) +
      // The files change when the reconstruction is re-run; a browser must not keep old ones.
      "\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n";
  bool sent = send_all(connection, response_head.data(), response_head.size());
  for (off_t left = status.st_size; sent && method == "GET" && left > 0;) {
    const ssize_t got = ::read(descriptor, buffer.data(), buffer.size());
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) break;  // the file shrank while being sent; the client sees a short body
    sent = send_all(connection, buffer.data(), std::size_t(got));
    left -= got;
  }
  ::close(descriptor);
  log().debug("viewer server: {} {} 200", method, target);
}

}  // namespace glint::viewer
