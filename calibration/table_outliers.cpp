// Outlier nodes of an error table (calibration/table_outliers.h).
#include "calibration/table_outliers.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <tuple>

#include <fmt/format.h>

#include "calibration/tolerances.h"

namespace smtcal {
namespace {

// A node's value predicted from its neighbours along one grid direction
// (`values(k)` at `lines[k]`, the node at index n), with the sum of the
// squared weights: how much the neighbours' noise the prediction carries
// (1/2 between two neighbours, 5 extrapolating at an edge).
struct Prediction {
  double value = 0;
  double noise_gain = 0;
};

template <typename Value>
std::optional<Prediction> AlongLine(const std::vector<double>& lines, std::size_t n, Value values) {
  const std::size_t count = lines.size();
  if (count < 3) return std::nullopt;
  std::size_t a = n - 1, b = n + 1;
  if (n == 0) a = 1, b = 2;
  if (n + 1 == count) a = n - 2, b = n - 1;
  const double wb = (lines[n] - lines[a]) / (lines[b] - lines[a]), wa = 1 - wb;
  return Prediction{wa * values(a) + wb * values(b), wa * wa + wb * wb};
}

std::optional<Prediction> Predicted(const AxisTable& t, const std::vector<double>& values, std::size_t i,
                                    std::size_t j) {
  std::optional<Prediction> along_x = AlongLine(t.xs, i, [&](std::size_t k) { return values[t.Index(k, j)]; });
  std::optional<Prediction> along_y = AlongLine(t.ys, j, [&](std::size_t k) { return values[t.Index(i, k)]; });
  if (along_x && along_y) {
    return Prediction{0.5 * (along_x->value + along_y->value), 0.25 * (along_x->noise_gain + along_y->noise_gain)};
  }
  if (along_x) return along_x;
  return along_y;
}

double StandardError(const AxisTable& t, std::size_t node) { return t.StandardErrorMm(node).value_or(0.0); }

// The simple slips a value may have suffered on its way into the file.
std::string LikelySlip(double value, double predicted, double scatter) {
  struct Candidate {
    double value;
    std::string what;
  };
  std::vector<Candidate> candidates;
  for (int shift : {-3, -2, -1, 1, 2, 3}) {
    const double fixed = value * std::pow(10.0, shift);
    candidates.push_back({fixed, shift == -3 ? "micrometres written as millimetres" : "a decimal point moved"});
  }
  candidates.push_back({-value, "a lost or added minus sign"});
  const Candidate* best = nullptr;
  for (const Candidate& c : candidates) {
    const double miss = std::abs(c.value - predicted);
    if (miss > std::max(kOutlierScatterFactor * scatter, 0.25 * std::abs(predicted))) continue;
    if (best == nullptr || miss < std::abs(best->value - predicted)) best = &c;
  }
  if (best == nullptr) return "";
  return fmt::format("{} ({:.6g} would fit)", best->what, best->value);
}

}  // namespace

std::vector<TableOutlier> FindTableOutliers(const ErrorTable& table) {
  constexpr int kMaxOutliersPerAxis = 20;  // beyond that the table is not a table with slips
  std::vector<TableOutlier> outliers;
  for (TableAxis axis : kTableAxes) {
    const AxisTable& t = table[axis];
    std::vector<double> values = t.error_mm;  // outliers found are replaced by their prediction
    auto residuals = [&](std::vector<std::optional<Prediction>>& predictions) {
      predictions.assign(values.size(), std::nullopt);
      for (std::size_t j = 0; j < t.ny(); ++j) {
        for (std::size_t i = 0; i < t.nx(); ++i) predictions[t.Index(i, j)] = Predicted(t, values, i, j);
      }
    };
    std::vector<std::optional<Prediction>> predictions;
    residuals(predictions);
    // The table's own scatter, from the file's values.
    std::vector<double> magnitudes;
    for (std::size_t node = 0; node < values.size(); ++node) {
      if (predictions[node]) magnitudes.push_back(std::abs(values[node] - predictions[node]->value));
    }
    if (magnitudes.empty()) continue;
    std::nth_element(magnitudes.begin(), magnitudes.begin() + static_cast<long>(magnitudes.size() / 2),
                     magnitudes.end());
    const double scatter = 1.4826 * magnitudes[magnitudes.size() / 2];
    for (int found = 0; found < kMaxOutliersPerAxis; ++found) {
      // The node that disagrees most, its difference scaled by how much noise
      // its prediction carries (an edge node extrapolated from a slipped
      // neighbour disagrees too, but less surely than the slipped node).
      std::optional<std::size_t> worst;
      double worst_score = 0;
      for (std::size_t node = 0; node < values.size(); ++node) {
        if (!predictions[node]) continue;
        const double r = std::abs(values[node] - predictions[node]->value);
        const double noise = StandardError(t, node);
        if (r <= kOutlierScatterFactor * scatter || r <= kOutlierNoiseFactor * noise || r <= kOutlierFloorMm) continue;
        const double score = r / std::sqrt(1 + predictions[node]->noise_gain);
        if (!worst || score > worst_score) worst = node, worst_score = score;
      }
      if (!worst) break;
      TableOutlier outlier;
      outlier.axis = axis;
      outlier.i = *worst % t.nx();
      outlier.j = *worst / t.nx();
      outlier.value_mm = t.error_mm[*worst];
      outlier.predicted_mm = predictions[*worst]->value;
      outlier.scatter_mm = std::max(scatter, StandardError(t, *worst));
      outlier.likely_slip = LikelySlip(outlier.value_mm, outlier.predicted_mm, outlier.scatter_mm);
      outliers.push_back(outlier);
      values[*worst] = outlier.predicted_mm;
      residuals(predictions);
    }
  }
  std::sort(outliers.begin(), outliers.end(), [](const TableOutlier& a, const TableOutlier& b) {
    return std::tie(a.axis, a.j, a.i) < std::tie(b.axis, b.j, b.i);
  });
  return outliers;
}

}  // namespace smtcal
