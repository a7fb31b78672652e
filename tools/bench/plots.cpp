#include "tools/bench/plots.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "tools/dataset/groundtruth_files.hpp"
#include "tools/eval/association.hpp"
#include "tools/eval/evaluation.hpp"

namespace fs = std::filesystem;

namespace parallax::bench {
namespace {

bool HaveGnuplot() { return std::system("gnuplot --version >/dev/null 2>&1") == 0; }

bool RunGnuplot(const fs::path& script) {
  const std::string command = "gnuplot '" + script.string() + "' >/dev/null 2>&1";
  return std::system(command.c_str()) == 0;
}

/// The two world axes along which the ground truth extends most (the "top view").
std::pair<int, int> ViewAxes(const Trajectory& gt) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const StampedPose& p : gt) {
    lo = lo.cwiseMin(p.T_w_c.Translation());
    hi = hi.cwiseMax(p.T_w_c.Translation());
  }
  const Eigen::Vector3d extent = hi - lo;
  int smallest = 0;
  for (int k = 1; k < 3; ++k) {
    if (extent[k] < extent[smallest]) smallest = k;
  }
  return {smallest == 0 ? 1 : 0, smallest == 2 ? 1 : 2};
}

const char* AxisName(int k) { return k == 0 ? "x" : (k == 1 ? "y" : "z"); }

/// trajectory.png and ate.png for one run; false if its trajectory cannot be read.
bool PlotTrajectory(const RunRecord& r, const fs::path& dir, std::vector<std::string>* pngs) {
  if (!r.figures.ok) return false;
  Trajectory gt;
  if (fs::is_directory(r.groundtruth)) {
    gt = ReadDatasetGroundTruth(r.groundtruth).poses;
  } else {
    gt = ReadTrajectoryFile({r.groundtruth, "", ""});
  }
  const Trajectory est = ReadTrajectoryFile({r.figures.estimate, "", ""});
  const auto pairs = AssociateByTimestamp(est, gt, 0.02);
  std::vector<Eigen::Vector3d> x, y;
  for (const auto& p : pairs) {
    x.push_back(est[p.estimate_index].T_w_c.Translation());
    y.push_back(gt[p.groundtruth_index].T_w_c.Translation());
  }
  if (x.size() < 3) return false;
  // The alignment the figures were computed with (Evaluate's, straight-line case included).
  const Sim3d S = Evaluate(est, gt, {}).S_gt_est;
  const auto [a, b] = ViewAxes(gt);
  std::ofstream data((dir / "trajectory.dat").string());
  for (const StampedPose& p : gt) {
    data << p.T_w_c.Translation()[a] << ' ' << p.T_w_c.Translation()[b] << '\n';
  }
  data << "\n\n";
  std::ofstream ate((dir / "ate.dat").string());
  for (std::size_t k = 0; k < x.size(); ++k) {
    const Eigen::Vector3d aligned = S * x[k];
    data << aligned[a] << ' ' << aligned[b] << '\n';
    ate << est[pairs[k].estimate_index].timestamp - est.front().timestamp << ' '
        << (aligned - y[k]).norm() << '\n';
  }
  data.close();
  ate.close();
  std::ofstream gp((dir / "trajectory.gp").string());
  gp << "set terminal pngcairo size 800,700\nset output '" << (dir / "trajectory.png").string()
     << "'\nset title '" << r.sequence << " (" << r.configuration
     << "): estimate after Sim(3) alignment'\nset size ratio -1\nset xlabel '" << AxisName(a)
     << " (m)'\nset ylabel '" << AxisName(b) << " (m)'\nset key outside bottom center horizontal\n"
     << "plot '" << (dir / "trajectory.dat").string()
     << "' index 0 with lines lw 2 lc rgb '#444444' title 'ground truth', '' index 1 with "
        "lines lw 1.5 lc rgb '#d62728' title 'Parallax'\n";
  gp << "set terminal pngcairo size 800,400\nset output '" << (dir / "ate.png").string()
     << "'\nset size noratio\nset title '" << r.sequence
     << ": position error after Sim(3) alignment'\nset xlabel 'time (s)'\nset ylabel 'ATE "
        "(m)'\nset key off\nplot '"
     << (dir / "ate.dat").string() << "' with lines lw 1.5 lc rgb '#1f77b4'\n";
  gp.close();
  if (!RunGnuplot(dir / "trajectory.gp")) return false;
  pngs->push_back((dir / "trajectory.png").string());
  pngs->push_back((dir / "ate.png").string());
  return true;
}

/// timing.png from the run's frames.csv.
void PlotTiming(const RunRecord& r, const fs::path& dir, std::vector<std::string>* pngs) {
  const fs::path csv = fs::path(r.run_dir) / "repeat0" / "frames.csv";
  if (!fs::exists(csv)) return;
  std::ofstream gp((dir / "timing.gp").string());
  gp << "set terminal pngcairo size 800,400\nset output '" << (dir / "timing.png").string()
     << "'\nset datafile separator ','\nset title '" << r.sequence
     << ": time per frame by stage'\nset xlabel 'frame'\nset ylabel 'ms'\nset key top right\n"
     << "plot '" << csv.string()
     << "' every ::1 using 1:6 with lines lc rgb '#2ca02c' title 'tracking', '' every ::1 using "
        "1:7 with lines lc rgb '#ff7f0e' title 'mapping (incl. backend)'\n";
  gp.close();
  if (RunGnuplot(dir / "timing.gp")) pngs->push_back((dir / "timing.png").string());
}

void PlotSummary(const BenchResult& result, const fs::path& dir, std::vector<std::string>* pngs) {
  std::ofstream data((dir / "summary.dat").string());
  for (const RunRecord& r : result.runs) {
    const std::string label =
        result.suite.configurations.size() > 1 ? r.sequence + "/" + r.configuration : r.sequence;
    data << '"' << label << "\" " << (r.figures.ok ? r.figures.ate_percent_of_path : 0.0) << ' '
         << (r.figures.ok ? 100.0 * r.figures.coverage : 0.0) << '\n';
  }
  data.close();
  std::ofstream gp((dir / "summary.gp").string());
  gp << "set terminal pngcairo size 1000,500\nset output '" << (dir / "summary.png").string()
     << "'\nset title 'Suite " << result.suite.name
     << ": ATE RMSE (% of path, Sim(3)) and coverage'\nset style data histograms\nset style "
        "fill solid 0.8\nset boxwidth 0.8\nset xtics rotate by -40\nset yrange [0:*]\nset ylabel "
        "'ATE (% of "
        "path)'\nset y2label 'frames posed (%)'\nset y2range [0:105]\nset y2tics\nset ytics "
        "nomirror\nset key top left\nplot '"
     << (dir / "summary.dat").string()
     << "' using 2:xtic(1) lc rgb '#1f77b4' title 'ATE % of path', '' using 0:3 axes x1y2 "
        "with points pt 7 ps 1.5 lc rgb '#d62728' title 'coverage'\n";
  gp.close();
  if (RunGnuplot(dir / "summary.gp")) pngs->push_back((dir / "summary.png").string());
}

}  // namespace

std::vector<std::string> WritePlots(const BenchResult& result, const std::string& out_dir) {
  std::vector<std::string> pngs;
  if (!HaveGnuplot()) {
    std::fprintf(stderr,
                 "bench: gnuplot is not installed (scripts/setup installs gnuplot-nox); "
                 "no plots\n");
    return pngs;
  }
  const fs::path root = fs::path(out_dir) / "plots";
  for (const RunRecord& r : result.runs) {
    const fs::path dir =
        root /
        (result.suite.configurations.size() > 1 ? r.sequence + "_" + r.configuration : r.sequence);
    fs::create_directories(dir);
    try {
      PlotTrajectory(r, dir, &pngs);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench: no trajectory plot for %s: %s\n", r.sequence.c_str(), e.what());
    }
    PlotTiming(r, dir, &pngs);
  }
  fs::create_directories(root);
  PlotSummary(result, root, &pngs);
  return pngs;
}

}  // namespace parallax::bench
