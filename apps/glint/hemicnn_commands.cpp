// glint hemicnn: the HemiCNN's training data, training and evaluation (paper 1 §3.6, §4.1).
#include "commands.h"

namespace glint::app {

void register_hemicnn_commands(CLI::App& app) {
  CLI::App* hemicnn = app.add_subcommand(
      "hemicnn",
      "The HemiCNN (paper 1 §3.6): make its training data from rendered sequences, train it,\n"
      "evaluate it, probe its colours. Run 'glint hemicnn <command> --help'.");
  hemicnn->require_subcommand(1);
  register_hemicnn_dataset(*hemicnn);
  register_hemicnn_train(*hemicnn);
  register_hemicnn_predict(*hemicnn);
  register_hemicnn_probe(*hemicnn);
}

}  // namespace glint::app
