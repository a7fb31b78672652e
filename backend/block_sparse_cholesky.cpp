#include "backend/block_sparse_cholesky.hpp"

#include <omp.h>
#include <suitesparse/cholmod.h>

#include <algorithm>
#include <stdexcept>

#include "core/check.hpp"

namespace parallax {

BlockSparseSymmetric::BlockSparseSymmetric(int num_blocks, int block_size,
                                           const std::vector<std::pair<int, int>>& off_diagonal)
    : num_blocks_(num_blocks), block_size_(block_size) {
  CheckArgument(num_blocks >= 0 && block_size >= 1, "BlockSparseSymmetric: bad dimensions");
  block_rows_.resize(static_cast<std::size_t>(num_blocks));
  for (auto [r, c] : off_diagonal) {
    CheckArgument(r != c && r >= 0 && c >= 0 && r < num_blocks && c < num_blocks,
                  "BlockSparseSymmetric: off-diagonal block out of range");
    if (r > c) std::swap(r, c);
    block_rows_[static_cast<std::size_t>(c)].push_back(r);
  }
  const auto b = static_cast<std::size_t>(block_size);
  col_start_.assign(static_cast<std::size_t>(num_blocks) * b + 1, 0);
  diagonal_index_.resize(static_cast<std::size_t>(num_blocks) * b);
  for (int c = 0; c < num_blocks; ++c) {
    auto& rows = block_rows_[static_cast<std::size_t>(c)];
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    rows.push_back(c);  // the diagonal block, last
    for (int k = 0; k < block_size; ++k) {
      const int column = c * block_size + k;
      const auto col = static_cast<std::size_t>(column);
      col_start_[col + 1] = col_start_[col];
      for (int r : rows) {
        const int height = r == c ? k + 1 : block_size;
        for (int i = 0; i < height; ++i) row_index_.push_back(r * block_size + i);
        col_start_[col + 1] += height;
      }
      diagonal_index_[col] = col_start_[col + 1] - 1;
    }
  }
  values_.assign(row_index_.size(), 0.0);
}

int BlockSparseSymmetric::Slot(int r, int c) const {
  if (r > c) std::swap(r, c);
  const auto& rows = block_rows_[static_cast<std::size_t>(c)];
  const auto it = std::lower_bound(rows.begin(), rows.end(), r);
  return it != rows.end() && *it == r ? static_cast<int>(it - rows.begin()) : -1;
}

void BlockSparseSymmetric::SetZero() { std::fill(values_.begin(), values_.end(), 0.0); }

Eigen::VectorXd BlockSparseSymmetric::DampDiagonal(double lambda, double min_diagonal) {
  Eigen::VectorXd added(Dimension());
  for (int k = 0; k < Dimension(); ++k) {
    double& d = values_[static_cast<std::size_t>(diagonal_index_[static_cast<std::size_t>(k)])];
    added[k] = lambda * std::max(d, min_diagonal);
    d += added[k];
  }
  return added;
}

void BlockSparseSymmetric::AddToDiagonal(const Eigen::VectorXd& d) {
  for (int k = 0; k < Dimension(); ++k) {
    values_[static_cast<std::size_t>(diagonal_index_[static_cast<std::size_t>(k)])] += d[k];
  }
}

Eigen::VectorXd BlockSparseSymmetric::Multiply(const Eigen::VectorXd& x) const {
  Eigen::VectorXd y = Eigen::VectorXd::Zero(Dimension());
  for (int col = 0; col < Dimension(); ++col) {
    for (int p = col_start_[static_cast<std::size_t>(col)];
         p < col_start_[static_cast<std::size_t>(col) + 1]; ++p) {
      const int row = row_index_[static_cast<std::size_t>(p)];
      const double v = values_[static_cast<std::size_t>(p)];
      y[row] += v * x[col];
      if (row != col) y[col] += v * x[row];
    }
  }
  return y;
}

Eigen::MatrixXd BlockSparseSymmetric::ToDense() const {
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(Dimension(), Dimension());
  for (int col = 0; col < Dimension(); ++col) {
    for (int p = col_start_[static_cast<std::size_t>(col)];
         p < col_start_[static_cast<std::size_t>(col) + 1]; ++p) {
      const int row = row_index_[static_cast<std::size_t>(p)];
      A(row, col) = A(col, row) = values_[static_cast<std::size_t>(p)];
    }
  }
  return A;
}

// CHOLMOD state: the common block, the matrix shell (pointing into BlockSparseSymmetric's
// arrays would need const_cast; a copy of the values per factorisation is cheap next to it)
// and the factor, whose symbolic part is kept between factorisations.
struct SymmetricSolver::Cholmod {
  cholmod_common common{};
  cholmod_sparse* A = nullptr;
  cholmod_factor* L = nullptr;
  Cholmod() {
    cholmod_start(&common);
    common.print = 0;
    common.error_handler = nullptr;
    common.nmethods = 1;  // AMD only: deterministic and enough for pose graphs
    common.method[0].ordering = CHOLMOD_AMD;
    common.postorder = 1;
    // LL' always: a simplicial LDL' would factor an indefinite matrix without complaint,
    // and LM relies on the failure to raise its damping.
    common.supernodal = CHOLMOD_SUPERNODAL;
  }
  ~Cholmod() {
    Free();
    cholmod_finish(&common);
  }
  Cholmod(const Cholmod&) = delete;
  Cholmod& operator=(const Cholmod&) = delete;
  void Free() {
    if (L) cholmod_free_factor(&L, &common);
    if (A) cholmod_free_sparse(&A, &common);
  }
};

SymmetricSolver::SymmetricSolver(LinearSolverKind kind) : kind_(kind) {
  if (kind_ == LinearSolverKind::kCholmod) cholmod_ = std::make_unique<Cholmod>();
}

SymmetricSolver::~SymmetricSolver() = default;

void SymmetricSolver::Reset() {
  if (cholmod_) cholmod_->Free();
}

bool SymmetricSolver::Factorize(const BlockSparseSymmetric& A) {
  if (kind_ == LinearSolverKind::kDense) {
    dense_.compute(A.ToDense());
    return dense_.info() == Eigen::Success;
  }
  Cholmod& c = *cholmod_;
  // CHOLMOD's supernodal loops ask OpenMP for 4 threads (a compile-time constant); dynamic
  // adjustment caps them at the cores this thread may run on instead of oversubscribing
  // them (docs/benchmarks.md, "Pose graph"). The setting belongs to the calling thread.
  omp_set_dynamic(1);
  const auto n = static_cast<std::size_t>(A.Dimension());
  const std::size_t nnz = A.Values().size();
  if (!c.A) {
    c.A = cholmod_allocate_sparse(n, n, nnz, 1, 1, 1, CHOLMOD_REAL, &c.common);
    if (!c.A) throw std::bad_alloc();
    std::copy(A.ColumnStarts().begin(), A.ColumnStarts().end(), static_cast<int*>(c.A->p));
    std::copy(A.RowIndices().begin(), A.RowIndices().end(), static_cast<int*>(c.A->i));
  }
  std::copy(A.Values().begin(), A.Values().end(), static_cast<double*>(c.A->x));
  if (!c.L) {
    c.L = cholmod_analyze(c.A, &c.common);
    if (!c.L) throw std::runtime_error("CHOLMOD: symbolic analysis failed");
  }
  const int ok = cholmod_factorize(c.A, c.L, &c.common);
  return ok != 0 && c.common.status == CHOLMOD_OK && c.L->minor == n;
}

Eigen::VectorXd SymmetricSolver::Solve(const Eigen::VectorXd& b) {
  if (kind_ == LinearSolverKind::kDense) return dense_.solve(b);
  Cholmod& c = *cholmod_;
  cholmod_dense* rhs =
      cholmod_allocate_dense(static_cast<std::size_t>(b.size()), 1,
                             static_cast<std::size_t>(b.size()), CHOLMOD_REAL, &c.common);
  if (!rhs) throw std::bad_alloc();
  std::copy(b.data(), b.data() + b.size(), static_cast<double*>(rhs->x));
  cholmod_dense* x = cholmod_solve(CHOLMOD_A, c.L, rhs, &c.common);
  cholmod_free_dense(&rhs, &c.common);
  if (!x) throw std::runtime_error("CHOLMOD: solve failed");
  Eigen::VectorXd out(b.size());
  std::copy(static_cast<const double*>(x->x), static_cast<const double*>(x->x) + b.size(),
            out.data());
  cholmod_free_dense(&x, &c.common);
  return out;
}

}  // namespace parallax
