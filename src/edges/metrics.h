#pragma once
// Classification scores of thesis §5.5.2: Precision, Recall, MCC, F1, Accuracy, IoU, for one
// class taken as "positive" against everything else.
#include <cstddef>
#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

namespace glint::edges {

// Which labels count as positive in an evaluation.
enum class EvalTask {
  sharp,     // positive = sharp edge (1); boundary predictions count as negative
  boundary,  // positive = boundary (2)
  edge,      // positive = sharp or boundary (1 or 2)
};
EvalTask parse_eval_task(const std::string& name);  // glint::Error for an unknown name
std::string to_string(EvalTask task);
bool is_positive(std::uint8_t label, EvalTask task);

struct BinaryScores {
  std::size_t true_positives = 0, false_positives = 0, true_negatives = 0, false_negatives = 0;
  double precision = 0, recall = 0, mcc = 0, f1 = 0, accuracy = 0, iou = 0;
};

// Scores predicted against true labels (same length, else glint::Error). Conventions for empty
// denominators: when neither truth nor prediction has a positive, precision, recall, F1 and IoU
// are 1; otherwise an empty denominator gives 0. MCC is 0 when any marginal is empty.
BinaryScores score(const std::vector<std::uint8_t>& predicted,
                   const std::vector<std::uint8_t>& truth, EvalTask task);

// The scores of the confusion counts held in `counts` (the other fields are ignored).
BinaryScores scores_from_counts(BinaryScores counts);

nlohmann::json to_json(const BinaryScores& scores);

// Median and mean of each score over files, and the scores of all points pooled (the counts
// summed over files: meaningful where many files have no positive at all).
struct ScoreSummary {
  BinaryScores median, mean, pooled;
};
ScoreSummary summarise(const std::vector<BinaryScores>& per_file);

}  // namespace glint::edges
