#pragma once
// Helpers of the viewer tests: a made-up page folder with every file the page needs, and a
// minimal HTTP client over a raw socket.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "viewer/static_site.h"

namespace glint::test {

inline void write_text(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

// FOLDER/page with every kRequiredPageFiles entry (its own name as content) and FOLDER/out/
// scene.glb ("glb bytes").
inline void make_site_files(const std::filesystem::path& folder) {
  for (const char* file : viewer::kRequiredPageFiles) write_text(folder / "page" / file, file);
  write_text(folder / "out" / "scene.glb", "glb bytes");
}

// A connected socket to 127.0.0.1:port, or -1.
inline int connect_local(int port) {
  const int connection = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(std::uint16_t(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(connection, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    ::close(connection);
    return -1;
  }
  return connection;
}

// Sends `request` as is and returns everything the server sends until it closes.
inline std::string http_exchange(int port, const std::string& request) {
  const int connection = connect_local(port);
  if (connection < 0) return "";
  ::send(connection, request.data(), request.size(), MSG_NOSIGNAL);
  std::string response;
  char buffer[4096];
  for (ssize_t got; (got = ::recv(connection, buffer, sizeof buffer, 0)) > 0;)
    response.append(buffer, std::size_t(got));
  ::close(connection);
  return response;
}

inline std::string get(int port, const std::string& target, const std::string& method = "GET") {
  return http_exchange(port, method + " " + target + " HTTP/1.1\r\nHost: localhost\r\n\r\n");
}

// The body of a response (after the blank line).
inline std::string body_of(const std::string& response) {
  const std::size_t end = response.find("\r\n\r\n");
  return end == std::string::npos ? "" : response.substr(end + 4);
}

}  // namespace glint::test
