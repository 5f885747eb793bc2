#pragma once
// A small static HTTP/1.1 server for `glint view`: GET (and HEAD) of a StaticSite's files on a
// local address, one short-lived thread per connection, every response `Connection: close`.
// Anything else is refused: other methods 405, a path that could leave the site or names no
// file 404, a request head over 16 KiB 431, more than max_connections at once 503. A client that
// sends nothing is dropped after idle_timeout_s. Meant for one user's browser on 127.0.0.1, not
// for the open network (no TLS, no authentication).
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <set>
#include <string>

#include "viewer/static_site.h"

namespace glint::viewer {

struct ServerParams {
  std::string host = "127.0.0.1";  // an IPv4 address; 127.0.0.1 keeps the page on this machine
  int port = 8000;                 // 0: any free port (port() tells which)
  int max_connections = 32;        // served at once; more are answered 503
  int idle_timeout_s = 10;         // a connection that sends or takes nothing this long is closed
};

class HttpServer {
 public:
  // Binds and listens; throws glint::Error "HOST:PORT" with the reason (port in use, not a
  // local address, no permission).
  HttpServer(const StaticSite& site, ServerParams params = {});
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  int port() const { return port_; }
  std::string url() const;  // http://HOST:PORT/

  // Serves until stop(); then closes the open connections and waits for their threads.
  void serve();
  // Ends serve() from any thread or a signal handler (it only writes to a pipe).
  void stop() noexcept;

  // Requests answered so far (any status).
  long requests() const { return requests_.load(); }

 private:
  void handle(int connection);
  void answer(int connection);

  const StaticSite& site_;
  ServerParams params_;
  int listener_ = -1;
  int wake_pipe_[2] = {-1, -1};
  int port_ = 0;
  std::atomic<long> requests_{0};
  std::mutex mutex_;
  std::condition_variable finished_;
  std::set<int> open_;  // connections being served
};

}  // namespace glint::viewer
