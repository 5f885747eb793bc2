// glint: one executable, one subcommand per capability. Errors print one line and exit 1.
#include <CLI/CLI.hpp>
#include <cstdio>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <exception>
#include <new>

#include "cli_support.h"
#include "commands.h"
#include "core/build_info.h"
#include "core/distributed.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "core/log.h"
#include "core/parallel.h"
#include "core/progress.h"

int main(int argc, char** argv) {
#if defined(__GLIBC__)
  // Every frame allocates images of a few MB (the frame read, tracking's model view and pyramid,
  // re-renderings). glibc hands such memory back to the kernel when it is freed (chunks above
  // its mmap threshold, and a heap top beyond its trim threshold), so every allocation faulted
  // in and zeroed its pages again: 6 ms of a 512x424 re-rendering's maps on one core. Kept in
  // the heap, the next frame reuses them. (The TSDF and observation pools are mapped apart,
  // core/pool_memory.h.)
  mallopt(M_MMAP_THRESHOLD, 32 << 20);  // the largest glibc takes
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
  CLI::App app{
      "glint - practical real-time reflectance estimation toolkit.\n"
      "Online reflectance reconstruction from RGB-D (fuse, lights, reconstruct, hemicnn;\n"
      "render and synth make synthetic sequences with ground truth), locally-guided image\n"
      "denoising (denoise) and point-cloud edge/boundary detection (edges, BoundED).\n"
      "Run 'glint <command> --help' for the options of each command. The options below\n"
      "(--quiet, --threads, --log-level) go before or after the command:\n"
      "'glint --quiet edges classify a.ply -o b.ply' = 'glint edges classify a.ply -o b.ply -q'."};
  app.require_subcommand(1);
  app.set_version_flag(
      "--version", [] { return glint::describe_build(); },
      "The version, the optional parts compiled in, where models and plugins are");

  glint::app::remember_command_line(argc, argv);
  glint::app::CommonOptions common;
  app.add_flag("-q,--quiet", common.quiet, "No progress bars")->configurable();
  app.add_option("--threads", common.threads, "Worker threads (0 = all cores)")
      ->check(glint::app::kNonNegative);
  app.add_option("--log-level", common.log_level, "trace, debug, info, warn, error, off");
  // Options a command does not know pass up to its parent, so the global ones above are taken
  // after the command too. Commands inherit this when they are added, so it comes first.
  app.fallthrough();

  glint::app::register_edges_commands(app);
  glint::app::register_denoise_commands(app);
  glint::app::register_render_command(app);
  glint::app::register_synth_command(app);
  glint::app::register_fuse_command(app);
  glint::app::register_reconstruct_command(app);
  glint::app::register_hemicnn_commands(app);
  glint::app::register_lights_command(app);
  glint::app::register_export_command(app);
  glint::app::register_view_command(app);

  std::unique_ptr<tbb::global_control> thread_limit;
  app.parse_complete_callback([&] {
    glint::set_quiet(common.quiet);
    glint::set_log_level(common.log_level);
    thread_limit = glint::limit_threads(common.threads);
  });

  // Ctrl-C and SIGTERM stop a long job at its next check and remove its unfinished outputs.
  glint::install_interrupt_handlers();
  try {
    glint::refuse_mpi_launch_without_mpi();
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const glint::Interrupted& e) {
    std::fprintf(stderr, "glint: %s\n", e.what());
    return e.exit_status();
  } catch (const std::bad_alloc&) {
    // Allocations of images and clouds name themselves (glint::Error); this is any other one.
    std::fprintf(stderr,
                 "glint: error: out of memory (an allocation failed; try a smaller input, fewer "
                 "--threads, or a tiled mode where the command has one)\n");
    return 1;
  } catch (const glint::Error& e) {
    std::fprintf(stderr, "glint: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "glint: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
