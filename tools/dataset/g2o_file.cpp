#include "tools/dataset/g2o_file.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>

#include "tools/dataset/input_error.hpp"
#include "tools/dataset/text_lines.hpp"

namespace parallax {
namespace {

constexpr int kInformationEntries = 21;

SE3d PoseFromFields(const std::vector<double>& v, std::size_t first, const std::string& path,
                    int line) {
  const Eigen::Quaterniond q(v[first + 6], v[first + 3], v[first + 4], v[first + 5]);
  if (q.norm() < 1e-6) throw InputError(path, line, "quaternion has (near) zero norm");
  return SE3d(SO3d(q), Eigen::Vector3d(v[first], v[first + 1], v[first + 2]));
}

bool IsPositiveDefinite(const Eigen::Matrix<double, 6, 6>& m) {
  const Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(m);
  return llt.info() == Eigen::Success;
}

Matrix7d InformationFromFields(const std::vector<double>& v, std::size_t first,
                               const std::string& path, int line, bool* block_diagonal) {
  Eigen::Matrix<double, 6, 6> info;
  std::size_t k = first;
  for (int r = 0; r < 6; ++r) {
    for (int c = r; c < 6; ++c) info(r, c) = info(c, r) = v[k++];
  }
  *block_diagonal = false;
  if (!IsPositiveDefinite(info)) {
    info.topRightCorner<3, 3>().setZero();
    info.bottomLeftCorner<3, 3>().setZero();
    if (!IsPositiveDefinite(info)) {
      throw InputError(path, line,
                       "information matrix is not positive definite, not even its "
                       "translation and rotation blocks");
    }
    *block_diagonal = true;
  }
  Matrix7d out = Matrix7d::Zero();
  out.topLeftCorner<6, 6>() = info;
  return out;
}

std::int64_t ParseId(const std::string& text, const std::string& path, int line) {
  const double id = ParseDouble(text, path, line, "vertex id");
  if (id < 0 || id != std::floor(id) || id > 9e15) {
    throw InputError(path, line, "vertex id must be a non-negative integer, got " + text);
  }
  return static_cast<std::int64_t>(id);
}

}  // namespace

G2oGraph ReadG2oFile(const std::string& path) {
  G2oGraph out;
  std::optional<std::int64_t> first_vertex;
  bool any_fix = false;
  ForEachDataLine(path, [&](const std::string& line, int number) {
    std::istringstream in(line);
    std::string tag;
    in >> tag;
    const std::string rest = line.substr(line.find(tag) + tag.size());
    if (tag == "VERTEX_SE3:QUAT") {
      const auto f = SplitFields(rest);
      if (f.size() != 8) throw InputError(path, number, "VERTEX_SE3:QUAT needs 8 fields");
      const std::int64_t id = ParseId(f[0], path, number);
      if (out.graph.HasVertex(id)) {
        throw InputError(path, number, "duplicate vertex " + std::to_string(id));
      }
      const auto v = ParseNumbers(rest, path, number, 8);
      out.graph.SetVertex(id, Sim3d(PoseFromFields(v, 1, path, number)));
      if (!first_vertex) first_vertex = id;
    } else if (tag == "EDGE_SE3:QUAT") {
      const auto f = SplitFields(rest);
      if (f.size() != 9 + kInformationEntries) {
        throw InputError(path, number, "EDGE_SE3:QUAT needs 30 fields");
      }
      const auto v = ParseNumbers(rest, path, number, 9 + kInformationEntries);
      PoseGraphEdge edge;
      edge.i = ParseId(f[0], path, number);
      edge.j = ParseId(f[1], path, number);
      for (const std::int64_t id : {edge.i, edge.j}) {
        if (!out.graph.HasVertex(id)) {
          throw InputError(
              path, number,
              "edge names vertex " + std::to_string(id) + ", which is not defined before it");
        }
      }
      if (edge.i == edge.j) throw InputError(path, number, "edge from a vertex to itself");
      edge.S_i_j = Sim3d(PoseFromFields(v, 2, path, number));
      bool block_diagonal = false;
      edge.information = InformationFromFields(v, 9, path, number, &block_diagonal);
      out.block_diagonal_information += block_diagonal;
      out.graph.AddEdge(edge);
    } else if (tag == "FIX") {
      const auto f = SplitFields(rest);
      if (f.empty()) throw InputError(path, number, "FIX needs vertex ids");
      for (const auto& field : f) {
        const std::int64_t id = ParseId(field, path, number);
        if (!out.graph.HasVertex(id)) {
          throw InputError(path, number, "FIX names unknown vertex " + field);
        }
        out.graph.SetFixed(id, true);
      }
      any_fix = true;
    } else {
      throw InputError(
          path, number,
          "unsupported record '" + tag + "' (VERTEX_SE3:QUAT, EDGE_SE3:QUAT and FIX are read)");
    }
  });
  if (!first_vertex) throw InputError(path, "has no VERTEX_SE3:QUAT records");
  if (!any_fix) out.graph.SetFixed(*first_vertex, true);
  return out;
}

void WriteG2oFile(const std::string& path, const PoseGraph& graph) {
  std::ofstream out(path);
  if (!out) throw InputError(path, "cannot open for writing");
  const auto pose_text = [&](const Sim3d& S) {
    if (std::abs(S.Scale() - 1.0) > 1e-9) {
      throw InputError(path, "g2o SE(3) output needs scale 1 everywhere");
    }
    const Eigen::Quaterniond& q = S.Rotation().UnitQuaternion();
    const Eigen::Vector3d& t = S.Translation();
    return fmt::format("{} {} {} {} {} {} {}", t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  };
  for (const std::int64_t id : graph.VertexIds()) {
    out << "VERTEX_SE3:QUAT " << id << ' ' << pose_text(graph.Pose(id)) << '\n';
  }
  for (const std::int64_t id : graph.VertexIds()) {
    if (graph.IsFixed(id)) out << "FIX " << id << '\n';
  }
  for (const PoseGraphEdge& e : graph.Edges()) {
    out << "EDGE_SE3:QUAT " << e.i << ' ' << e.j << ' ' << pose_text(e.S_i_j);
    for (int r = 0; r < 6; ++r) {
      for (int c = r; c < 6; ++c) out << ' ' << fmt::format("{}", e.information(r, c));
    }
    out << '\n';
  }
  if (!out) throw InputError(path, "write failed");
}

}  // namespace parallax
