#include "commands.h"

namespace glint::app {

void register_edges_commands(CLI::App& app) {
  CLI::App* edges = app.add_subcommand(
      "edges",
      "BoundED: per-point non-edge / sharp-edge / boundary classification of point clouds "
      "(thesis ch. 5)");
  edges->require_subcommand(1);
  // One line per subcommand; each lives in apps/glint/edges_<name>.cpp.
  register_edges_classify(*edges);
  register_edges_features(*edges);
  register_edges_train(*edges);
  register_edges_synth(*edges);
  register_edges_eval(*edges);
  register_edges_label(*edges);
  register_edges_gate(*edges);
}

}  // namespace glint::app
