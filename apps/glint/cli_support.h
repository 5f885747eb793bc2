#pragma once
// Small helpers shared by the subcommands.
#include <string>
#include <vector>

namespace glint::app {

// Expands files and folders (recursively; *.ply *.xyz *.pts *.txt *.csv *.pcd, sorted) into a
// list of point-cloud files. A path that does not exist -> glint::Error naming it.
std::vector<std::string> expand_point_cloud_inputs(const std::vector<std::string>& paths);

// Where shipped models live: $GLINT_MODELS, else the source tree's models/ folder.
std::string models_directory();
// The shipped 3-class BoundED model, the default of classify and eval.
std::string default_edges_model();

// The command line as one string, for reports and model provenance (main() records it).
void remember_command_line(int argc, char** argv);
const std::string& command_line();

}  // namespace glint::app
