// The viewer's HTTP server (viewer/http_server.h) over real sockets on 127.0.0.1: files and
// their types, refusals (path traversal, other methods, malformed requests), a port in use, the
// connection limit, and stop() while clients hold idle connections.
#include "viewer/http_server.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <thread>

#include "core/error.h"
#include "support/error_of.h"
#include "viewer_test_support.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

class Server : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = fs::temp_directory_path() /
              ("glint_http_server_test_" +
               std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
               std::to_string(::getpid()));
    fs::remove_all(folder_);
    test::make_site_files(folder_);
    test::write_text(folder_ / "secret.txt", "secret");
    site_ = std::make_unique<viewer::StaticSite>(folder_ / "page", folder_ / "out" / "scene.glb");
  }
  void TearDown() override { fs::remove_all(folder_); }

  // Starts a server on a free port, serving in a thread until stop_serving().
  void start(viewer::ServerParams params = {}) {
    params.port = 0;
    server_ = std::make_unique<viewer::HttpServer>(*site_, params);
    serving_ = std::thread([this] { server_->serve(); });
  }
  void stop_serving() {
    server_->stop();
    serving_.join();
  }

  fs::path folder_;
  std::unique_ptr<viewer::StaticSite> site_;
  std::unique_ptr<viewer::HttpServer> server_;
  std::thread serving_;
};

TEST_F(Server, ServesThePageAndTheSceneWithTheirTypes) {
  start();
  const int port = server_->port();
  EXPECT_GT(port, 0);
  const std::string page = test::get(port, "/");
  EXPECT_EQ(page.rfind("HTTP/1.1 200 OK\r\n", 0), 0u) << page;
  EXPECT_NE(page.find("Content-Type: text/html"), std::string::npos) << page;
  EXPECT_EQ(test::body_of(page), "index.html");

  const std::string scene = test::get(port, "/scene.glb");
  EXPECT_NE(scene.find("Content-Type: model/gltf-binary"), std::string::npos) << scene;
  EXPECT_NE(scene.find("Content-Length: 9\r\n"), std::string::npos) << scene;
  EXPECT_EQ(test::body_of(scene), "glb bytes");

  const std::string module = test::get(port, "/three/addons/loaders/GLTFLoader.js?v=1");
  EXPECT_NE(module.find("Content-Type: text/javascript"), std::string::npos) << module;

  const std::string head = test::get(port, "/scene.glb", "HEAD");
  EXPECT_NE(head.find("Content-Length: 9\r\n"), std::string::npos) << head;
  EXPECT_EQ(test::body_of(head), "");
  stop_serving();
  EXPECT_EQ(server_->requests(), 4);
}

TEST_F(Server, RefusesTraversalOtherMethodsAndMalformedRequests) {
  start();
  const int port = server_->port();
  for (const char* target : {"/../secret.txt", "/%2e%2e/secret.txt", "/three/..%2f..%2fsecret.txt",
                             "/missing.js", "/three"})
    EXPECT_EQ(test::get(port, target).rfind("HTTP/1.1 404", 0), 0u) << target;
  const std::string post = test::get(port, "/", "POST");
  EXPECT_EQ(post.rfind("HTTP/1.1 405", 0), 0u) << post;
  EXPECT_NE(post.find("Allow: GET, HEAD"), std::string::npos) << post;
  EXPECT_EQ(test::http_exchange(port, "nonsense\r\n\r\n").rfind("HTTP/1.1 400", 0), 0u);
  const std::string huge = "GET / HTTP/1.1\r\nX: " + std::string(20000, 'x') + "\r\n\r\n";
  EXPECT_EQ(test::http_exchange(port, huge).rfind("HTTP/1.1 431", 0), 0u);
  stop_serving();
}

TEST_F(Server, PortInUseIsAClearError) {
  start();
  viewer::ServerParams taken;
  taken.port = server_->port();
  const Error error = test::error_of([&] { viewer::HttpServer(*site_, taken); });
  EXPECT_EQ(error.file(), "127.0.0.1:" + std::to_string(taken.port));
  EXPECT_NE(error.reason().find("port in use"), std::string::npos) << error.what();
  stop_serving();

  viewer::ServerParams not_an_address;
  not_an_address.host = "localhost:80";
  EXPECT_NE(
      test::error_of([&] { viewer::HttpServer(*site_, not_an_address); }).reason().find("IPv4"),
      std::string::npos);
}

TEST_F(Server, AnswersOverTheLimitWith503AndStopsWhileClientsHoldIdleConnections) {
  viewer::ServerParams params;
  params.max_connections = 1;
  start(params);
  const int idle = test::connect_local(server_->port());  // sends nothing, holds the one slot
  ASSERT_GE(idle, 0);
  std::string refused;
  // The idle connection is accepted asynchronously; ask until it holds the slot.
  for (int attempt = 0; attempt < 200 && refused.rfind("HTTP/1.1 503", 0) != 0; ++attempt) {
    refused = test::get(server_->port(), "/");
    if (refused.rfind("HTTP/1.1 503", 0) != 0) usleep(10000);
  }
  EXPECT_EQ(refused.rfind("HTTP/1.1 503", 0), 0u) << refused;
  // stop() returns although the idle client never sent a request (no waiting for its timeout).
  stop_serving();
  char byte;
  EXPECT_EQ(::recv(idle, &byte, 1, 0), 0);  // the server closed it
  ::close(idle);
}

}  // namespace
}  // namespace glint
