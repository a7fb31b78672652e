#pragma once
// Sparse Cholesky of a symmetric block matrix (the pose graph's normal equations) through
// CHOLMOD, with a dense twin for tests and small problems.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <memory>
#include <utility>
#include <vector>

namespace parallax {

/// The upper triangle of a symmetric matrix of `num_blocks` x `num_blocks` square blocks of
/// `block_size`, stored in compressed columns with a fixed pattern: the diagonal blocks and
/// the (r, c), r < c, blocks named at construction. Values are written in place through
/// Entry(), so the pattern (and CHOLMOD's symbolic analysis) is reused across iterations.
class BlockSparseSymmetric {
 public:
  /// `off_diagonal`: block pairs (r, c) with r != c in any order; duplicates are merged.
  BlockSparseSymmetric(int num_blocks, int block_size,
                       const std::vector<std::pair<int, int>>& off_diagonal);

  int NumBlocks() const { return num_blocks_; }
  int BlockSize() const { return block_size_; }
  int Dimension() const { return num_blocks_ * block_size_; }
  /// Slot of block (r, c), r <= c, inside block column c; -1 if the block is not stored.
  int Slot(int r, int c) const;
  /// Reference to entry (i, k) of block (r, c) with r < c, or r == c and i <= k; `slot` is
  /// Slot(r, c).
  double& Entry(int c, int slot, int i, int k) {
    const int column = c * block_size_ + k;
    const int offset = col_start_[static_cast<std::size_t>(column)] + slot * block_size_ + i;
    return values_[static_cast<std::size_t>(offset)];
  }
  void SetZero();
  /// Adds lambda * max(min_diagonal, H_kk) to every diagonal entry (Marquardt damping) and
  /// returns the damping added per entry.
  Eigen::VectorXd DampDiagonal(double lambda, double min_diagonal);
  void AddToDiagonal(const Eigen::VectorXd& d);
  /// y = A x (the full symmetric product).
  Eigen::VectorXd Multiply(const Eigen::VectorXd& x) const;
  Eigen::MatrixXd ToDense() const;

  const std::vector<int>& ColumnStarts() const { return col_start_; }
  const std::vector<int>& RowIndices() const { return row_index_; }
  const std::vector<double>& Values() const { return values_; }

 private:
  int num_blocks_;
  int block_size_;
  std::vector<std::vector<int>> block_rows_;  ///< per block column: sorted rows, diagonal last
  std::vector<int> col_start_;                ///< size Dimension() + 1
  std::vector<int> row_index_;
  std::vector<double> values_;
  std::vector<int> diagonal_index_;  ///< position of entry (k, k) in values_
};

/// Which factorisation solves the damped normal equations.
enum class LinearSolverKind {
  kCholmod,  ///< supernodal sparse Cholesky (SuiteSparse), symbolic analysis reused
  kDense,    ///< Eigen LLT of the dense matrix (tests, tiny graphs)
};

/// Solves A x = b for the symmetric positive-definite A held in a BlockSparseSymmetric.
class SymmetricSolver {
 public:
  explicit SymmetricSolver(LinearSolverKind kind);
  ~SymmetricSolver();
  SymmetricSolver(const SymmetricSolver&) = delete;
  SymmetricSolver& operator=(const SymmetricSolver&) = delete;

  /// Factorises A (symbolic analysis on the first call after Reset()); false when A is not
  /// positive definite.
  bool Factorize(const BlockSparseSymmetric& A);
  /// Solution of A x = b with the last successful factorisation.
  Eigen::VectorXd Solve(const Eigen::VectorXd& b);
  /// Forgets the symbolic analysis (the pattern changed).
  void Reset();

 private:
  struct Cholmod;
  LinearSolverKind kind_;
  std::unique_ptr<Cholmod> cholmod_;
  Eigen::LLT<Eigen::MatrixXd> dense_;
};

}  // namespace parallax
