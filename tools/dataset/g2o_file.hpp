#pragma once
// g2o's text format for 3-D pose graphs: VERTEX_SE3:QUAT, EDGE_SE3:QUAT and FIX records
// (docs/math/pose_graph.md, "g2o files").

#include <string>

#include "backend/pose_graph.hpp"

namespace parallax {

/// A pose graph read from a g2o file.
struct G2oGraph {
  PoseGraph graph;  ///< SE(3) vertices and edges (scale 1); rotation information on 2 vec(q)
  /// Edges whose information matrix was not positive definite and was replaced by its
  /// (translation, rotation) block diagonal.
  int block_diagonal_information = 0;
};

/// Reads VERTEX_SE3:QUAT id x y z qx qy qz qw (world-from-vertex), EDGE_SE3:QUAT i j x y z
/// qx qy qz qw and the 21 upper-triangular entries of the 6x6 information (translation
/// first), and FIX id. The first vertex in the file is fixed when no FIX record is given.
/// Throws InputError naming the file and line for an unknown record, a duplicate vertex, an
/// edge to a missing vertex, a bad number or an information matrix that is unusable even
/// block-diagonally.
G2oGraph ReadG2oFile(const std::string& path);

/// Writes the graph's vertices (ascending id) and edges in the same format; throws InputError
/// if the file cannot be written. Requires scale 1 everywhere (an SE(3) graph).
void WriteG2oFile(const std::string& path, const PoseGraph& graph);

}  // namespace parallax
