// Outlier nodes of an error table (calibration/table_outliers.h).
#include "calibration/table_outliers.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <tuple>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "calibration/sample_statistics.h"
#include "calibration/tolerances.h"

namespace smtcal {
namespace {

constexpr std::size_t kMaxOutliersPerAxis = 20;  // beyond that the table is not a table with slips

// A node's value predicted from its neighbours along one grid direction
// (`values(k)` at `lines[k]`, the node at index n).
struct Prediction {
  double value = 0;
};

template <typename Value>
std::optional<Prediction> AlongLine(const std::vector<double>& lines, std::size_t n, Value values) {
  const std::size_t count = lines.size();
  if (count < 3) return std::nullopt;
  std::size_t a = n - 1, b = n + 1;
  if (n == 0) a = 1, b = 2;
  if (n + 1 == count) a = n - 2, b = n - 1;
  const double wb = (lines[n] - lines[a]) / (lines[b] - lines[a]), wa = 1 - wb;
  return Prediction{wa * values(a) + wb * values(b)};
}

std::optional<Prediction> Predicted(const AxisTable& t, const std::vector<double>& values, std::size_t i,
                                    std::size_t j) {
  std::optional<Prediction> along_x = AlongLine(t.xs, i, [&](std::size_t k) { return values[t.Index(k, j)]; });
  std::optional<Prediction> along_y = AlongLine(t.ys, j, [&](std::size_t k) { return values[t.Index(i, k)]; });
  if (along_x && along_y) {
    return Prediction{0.5 * (along_x->value + along_y->value)};
  }
  if (along_x) return along_x;
  return along_y;
}

// The table's values with the nodes in `taken` replaced by what their
// neighbours predict, all at once: a prediction is linear in the values, so
// the taken values x solve x = A x + b (A: how each taken node's prediction
// depends on the other taken nodes, b: on the rest). Adjacent taken nodes
// then do not keep each other's slips. At most kMaxOutliersPerAxis
// unknowns; a singular system (a taken node predicted only from taken ones)
// gets its least-squares solution.
std::vector<double> Repaired(const AxisTable& t, const std::vector<std::size_t>& taken) {
  std::vector<double> values = t.error_mm;
  if (taken.empty()) return values;
  const auto n = static_cast<Eigen::Index>(taken.size());
  for (std::size_t node : taken) values[node] = 0;
  auto predict = [&](std::size_t node) {
    const std::optional<Prediction> p = Predicted(t, values, node % t.nx(), node / t.nx());
    return p ? p->value : 0.0;
  };
  Eigen::MatrixXd a(n, n);
  Eigen::VectorXd b(n);
  for (Eigen::Index f = 0; f < n; ++f) b(f) = predict(taken[static_cast<std::size_t>(f)]);
  for (Eigen::Index g = 0; g < n; ++g) {
    values[taken[static_cast<std::size_t>(g)]] = 1;
    for (Eigen::Index f = 0; f < n; ++f) a(f, g) = predict(taken[static_cast<std::size_t>(f)]) - b(f);
    values[taken[static_cast<std::size_t>(g)]] = 0;
  }
  const Eigen::VectorXd x = (Eigen::MatrixXd::Identity(n, n) - a).colPivHouseholderQr().solve(b);
  for (Eigen::Index f = 0; f < n; ++f) values[taken[static_cast<std::size_t>(f)]] = x(f);
  return values;
}

// The outliers of one axis table.
void FindInAxis(TableAxis axis, const AxisTable& t, std::vector<TableOutlier>& outliers) {
  const std::size_t nodes = t.error_mm.size();
  std::vector<std::optional<Prediction>> predictions(nodes);
  auto predict_all = [&](const std::vector<double>& values) {
    for (std::size_t j = 0; j < t.ny(); ++j) {
      for (std::size_t i = 0; i < t.nx(); ++i) predictions[t.Index(i, j)] = Predicted(t, values, i, j);
    }
  };
  predict_all(t.error_mm);
  // The table's own scatter, from the file's values, and its typical noise.
  std::vector<double> magnitudes, standard_errors, stddevs;
  for (std::size_t node = 0; node < nodes; ++node) {
    if (predictions[node]) magnitudes.push_back(std::abs(t.error_mm[node] - predictions[node]->value));
    if (std::optional<double> se = t.StandardErrorMm(node)) {
      standard_errors.push_back(*se);
      stddevs.push_back(t.stddev_mm[node].value_or(0.0));
    }
  }
  if (magnitudes.empty()) return;
  const double scatter = kMadToSigma * Median(magnitudes);
  const double noise_cap = standard_errors.empty() ? 0.0 : kOutlierNoiseCapFactor * Median(standard_errors);
  auto noise_of = [&](std::size_t node) { return std::min(t.StandardErrorMm(node).value_or(0.0), noise_cap); };
  // How far a node's value as written is from its prediction, when that is
  // beyond every threshold; 0 otherwise.
  auto excess = [&](std::size_t node) {
    if (!predictions[node]) return 0.0;
    const double r = std::abs(t.error_mm[node] - predictions[node]->value);
    if (r <= kOutlierScatterFactor * scatter || r <= kOutlierNoiseFactor * noise_of(node) || r <= kOutlierFloorMm) {
      return 0.0;
    }
    return r;
  };

  // Forward: of the nodes that disagree beyond the thresholds, the one whose
  // repair explains the most disagreement is taken: repairing a slipped
  // node also removes what it did to its neighbours' predictions (an edge
  // node extrapolated from it is off by twice its slip), while repairing
  // one of those neighbours leaves the slip in place. Each node at most
  // once; the nodes taken are repaired (together) before the next search.
  std::vector<bool> taken(nodes, false);
  std::vector<std::size_t> found;
  std::vector<double> values = t.error_mm;
  // The sum of squared disagreements (value minus prediction) over the
  // nodes not taken whose predictions `node` enters (its row and column, two
  // nodes either way) and `node` itself: the nodes taken hold repaired
  // values, no data to disagree with.
  auto local_disagreement = [&](const std::vector<double>& v, std::size_t node) {
    const std::size_t i = node % t.nx(), j = node / t.nx();
    double sum = 0;
    auto add = [&](std::size_t ki, std::size_t kj) {
      const std::size_t k = t.Index(ki, kj);
      if (taken[k] && k != node) return;
      const std::optional<Prediction> p = Predicted(t, v, ki, kj);
      if (p) sum += (v[k] - p->value) * (v[k] - p->value);
    };
    // The node itself, then two nodes either way along its row and column.
    add(i, j);
    for (std::size_t d = 1; d <= 2; ++d) {
      if (i >= d) add(i - d, j);
      if (i + d < t.nx()) add(i + d, j);
      if (j >= d) add(i, j - d);
      if (j + d < t.ny()) add(i, j + d);
    }
    return sum;
  };
  for (std::size_t step = 0; step < kMaxOutliersPerAxis; ++step) {
    std::optional<std::size_t> best;
    double best_gain = 0;
    for (std::size_t node = 0; node < nodes; ++node) {
      if (taken[node] || excess(node) == 0) continue;
      std::vector<double> trial = values;
      trial[node] = predictions[node]->value;
      // Against the node's value as written: that is what is on trial.
      std::vector<double> as_written = values;
      as_written[node] = t.error_mm[node];
      const double gain = local_disagreement(as_written, node) - local_disagreement(trial, node);
      if (!best || gain > best_gain) best = node, best_gain = gain;
    }
    if (!best) break;
    taken[*best] = true;
    found.push_back(*best);
    values = Repaired(t, found);
    predict_all(values);
  }
  // Backward: a node taken early only because a slipped neighbour spoiled
  // its prediction agrees with its repaired neighbours: it is given back,
  // one at a time, the worst-fitting first, until every node taken still
  // disagrees with its repaired neighbours.
  for (bool gave_back = true; gave_back;) {
    gave_back = false;
    std::optional<std::size_t> fits;
    double fits_by = 0;
    for (std::size_t k = 0; k < found.size(); ++k) {
      const double r = excess(found[k]);
      const double by = std::abs(t.error_mm[found[k]] - predictions[found[k]]->value);
      if (r == 0 && (!fits || by < fits_by)) fits = k, fits_by = by;
    }
    if (fits) {
      found.erase(found.begin() + static_cast<long>(*fits));
      values = Repaired(t, found);
      predict_all(values);
      gave_back = true;
    }
  }
  for (std::size_t node : found) {
    TableOutlier outlier;
    outlier.axis = axis;
    outlier.i = node % t.nx();
    outlier.j = node / t.nx();
    outlier.value_mm = t.error_mm[node];
    outlier.predicted_mm = values[node];
    const double se = t.StandardErrorMm(node).value_or(0.0);
    outlier.scatter_mm = std::max(scatter, noise_of(node));
    if (se > noise_cap && noise_cap > 0) {
      // Its mean is unsound: one of its measurements is probably off, which
      // no slip of the mean itself describes.
      outlier.likely_slip = fmt::format(
          "a bad measurement among its {} (they scatter {:.4f} mm, its axis's nodes typically {:.4f} mm; smtcal "
          "table build on the raw measurements names it)",
          t.count[node], t.stddev_mm[node].value_or(0.0), Median(stddevs));
    } else {
      outlier.likely_slip = FindLikelySlip(outlier.value_mm, outlier.predicted_mm,
                                           SingleValueFitMm(outlier.predicted_mm, outlier.scatter_mm))
                                .Describe();
    }
    outliers.push_back(outlier);
  }
}

}  // namespace

std::vector<TableOutlier> FindTableOutliers(const ErrorTable& table) {
  std::vector<TableOutlier> outliers;
  for (TableAxis axis : kTableAxes) FindInAxis(axis, table[axis], outliers);
  std::sort(outliers.begin(), outliers.end(), [](const TableOutlier& a, const TableOutlier& b) {
    return std::tie(a.axis, a.j, a.i) < std::tie(b.axis, b.j, b.i);
  });
  return outliers;
}

ErrorTable WithOutliersRepaired(const ErrorTable& table, const std::vector<TableOutlier>& outliers) {
  ErrorTable repaired = table;
  for (const TableOutlier& outlier : outliers) {
    AxisTable& t = repaired.axes[static_cast<int>(outlier.axis)];
    t.error_mm[t.Index(outlier.i, outlier.j)] = outlier.predicted_mm;
  }
  return repaired;
}

}  // namespace smtcal
