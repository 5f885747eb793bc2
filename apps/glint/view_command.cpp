// glint view: the three.js viewer of a reconstruction's scene.glb, served on this machine or
// written as a static copy.
#include <csignal>
#include <filesystem>
#include <memory>

#include "commands.h"
#include "core/error.h"
#include "core/log.h"
#include "core/resources.h"
#include "viewer/http_server.h"
#include "viewer/static_site.h"

namespace glint::app {
namespace {

namespace fs = std::filesystem;

struct ViewOptions {
  std::string scene;  // OUT folder or a .glb file
  std::string write_html;
  viewer::ServerParams server;
};

// The server that SIGINT / SIGTERM stop (HttpServer::stop only writes to a pipe).
viewer::HttpServer* running_server = nullptr;
extern "C" void stop_running_server(int) {
  if (running_server) running_server->stop();
}

fs::path scene_glb_of(const std::string& scene) {
  const fs::path path(scene);
  if (fs::is_directory(path)) return path / "scene.glb";
  if (!fs::exists(path)) throw Error(scene, "", "no such folder or file");
  return path;
}

void run_view(const ViewOptions& options) {
  const viewer::StaticSite site(web_directory(), scene_glb_of(options.scene));
  if (!options.write_html.empty()) {
    viewer::write_static_copy(site, options.write_html);
    log().info(
        "wrote {}: serve it with any static file server, e.g. "
        "`python3 -m http.server -b 127.0.0.1 -d {}` (not file://: browsers refuse ES "
        "modules from files)",
        options.write_html, options.write_html);
    return;
  }
  viewer::HttpServer server(site, options.server);
  running_server = &server;
  struct sigaction stop {
  }, previous_interrupt{}, previous_terminate{};
  stop.sa_handler = stop_running_server;  // no SA_RESTART: poll() returns, serve() ends
  sigemptyset(&stop.sa_mask);
  sigaction(SIGINT, &stop, &previous_interrupt);
  sigaction(SIGTERM, &stop, &previous_terminate);
  log().info("serving {} at {} (Ctrl+C stops)", site.scene_glb().string(), server.url());
  try {
    server.serve();
  } catch (...) {
    running_server = nullptr;
    sigaction(SIGINT, &previous_interrupt, nullptr);
    sigaction(SIGTERM, &previous_terminate, nullptr);
    throw;
  }
  running_server = nullptr;
  sigaction(SIGINT, &previous_interrupt, nullptr);
  sigaction(SIGTERM, &previous_terminate, nullptr);
  log().info("stopped after {} requests", server.requests());
}

}  // namespace

void register_view_command(CLI::App& app) {
  auto options = std::make_shared<ViewOptions>();
  CLI::App* command = app.add_subcommand(
      "view",
      "Show a reconstruction in the browser: serves a three.js page with OUT/scene.glb on\n"
      "127.0.0.1 (open the printed address). Orbit with the mouse; click a light's handle and\n"
      "drag its arrows to move it (the scene relights live); click the model for the picked\n"
      "segment's Ward kd, ks, alpha; switch between shaded, albedo, diffuse, specular and\n"
      "segment views. --write-html DIR writes the same page, its three.js modules and the GLB\n"
      "as plain files for any static file server instead.\n"
      "Example: glint view out/bunnies   |   glint view out/bunnies --write-html site/");
  command
      ->add_option("scene", options->scene,
                   "A reconstruction folder (glint reconstruct -o OUT) or a .glb file")
      ->required();
  command->add_option("--port", options->server.port, "Port to serve on (0: any free one)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  command
      ->add_option("--host", options->server.host,
                   "Address to listen on; the default keeps the page on this machine")
      ->capture_default_str();
  command->add_option("--write-html", options->write_html,
                      "Write a self-contained static copy (page, three.js modules, scene.glb) "
                      "into this folder and exit, instead of serving");
  command->callback([options] { run_view(*options); });
}

}  // namespace glint::app
