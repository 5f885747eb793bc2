#pragma once
// Small helpers shared by the subcommands.
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace glint::app {

// Expands files and folders (recursively; *.ply *.xyz *.pts *.txt *.csv *.pcd, sorted) into a
// list of point-cloud files. A path that does not exist -> glint::Error naming it.
std::vector<std::string> expand_point_cloud_inputs(const std::vector<std::string>& paths);

// The shipped 3-class BoundED model, the default of classify and eval (core/resources.h finds
// the models folder).
std::string default_edges_model();

// Option checks for numbers > 0 and >= 0, shown as POSITIVE and NONNEGATIVE in --help like
// CLI11's PositiveNumber and NonNegativeNumber, whose errors read "Value -1 not in range
// 0.000000 to 1797693...(a 309-digit bound)"; these say "must be more than 0, got -1".
extern const CLI::Validator kPositive;
extern const CLI::Validator kNonNegative;
// A file to write: not an existing folder, and no file where one of its folders should be
// (missing folders are created when it is written). Checked when the command line is read, so
// that a long run does not end in "cannot move the finished file into place".
extern const CLI::Validator kOutputFile;

// The command line as one string, for reports and model provenance (main() records it).
void remember_command_line(int argc, char** argv);
const std::string& command_line();

}  // namespace glint::app
