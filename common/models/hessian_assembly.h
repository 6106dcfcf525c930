// Assembly of chain energies (curve2d, thread3d) from small per-term derivatives.
//
// A chain energy is a sum of terms that each touch a few nodes: a stretching term two
// nodes, a bending term three. Each term is differentiated in closed form with respect
// to its own few "local" variables; HessianAssembly then adds the local gradient and
// Hessian into the global E_x, E_xx (sparse), E_u, E_xu and E_uu.
//
// Variables are numbered in one "generalised" index space: [0, num_states) are the state
// x, [num_states, num_states + num_controls) the controls u, and -1 marks a coordinate
// that is held fixed (p_0, the clamped y_1/z_1): such a coordinate simply has no column.
//
// The full symmetric pattern of E_xx is built once (Finalize), together with, for every
// term, the index into SparseMatrix::valuePtr() of each (local i, local j) pair, so that
// adding a term's Hessian is a table look-up without search or allocation.
//
// Dynamic terms (self-contact, contact_terms.h): after Finalize() a model may replace a
// set of extra terms (SetDynamicTerms) — the segment pairs near contact — and the pattern
// becomes the fixed terms' plus theirs. That allocates and re-indexes the fixed terms'
// tables (O(nnz + runs)), so a model does it only when its set changes; PatternVersion()
// counts the changes, and a solver re-analyses its factorisation when it moves.
#pragma once

#include <algorithm>

#include <cmath>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "numeric/types.h"

namespace snapthread::internal {

class HessianAssembly {
 public:
  // Most variables one term can touch (thread3d's bending term next to the grip touches
  // 3 + 3 + 7 = 13: two free nodes, then s, (X, Y, Z) and (dx, dy, dz)).
  static constexpr int kMaxTermVars = 16;
  // AddTerm accepts up to this many (a term over two segments' 12 coordinates and a free
  // rod's 12 controls); the local buffers of the elastic terms stay kMaxTermVars. The
  // self-contact pairs are dynamic terms over their state coordinates only (at most 12).
  static constexpr int kMaxPairTermVars = 24;

  HessianAssembly() = default;
  HessianAssembly(int num_states, int num_controls);

  // Registers a term whose local variables are vars[0..count) (generalised indices,
  // -1 for fixed coordinates). Returns the term id (0, 1, ... in call order).
  int AddTerm(const int* vars, int count);
  // Builds the pattern and the scatter tables. Call once, after the last AddTerm.
  void Finalize();

  // Before Finalize(): the model will call SetDynamicTerms, so the pattern may change
  // and Bandwidth() is not known (-1).
  void EnableDynamicTerms() { dynamic_ = true; }
  bool DynamicTerms() const { return dynamic_; }
  // Replaces the dynamic terms (after Finalize(), EnableDynamicTerms() before it): term
  // FixedTerms() + k has the variables vars[begin[k] .. begin[k + 1]) (begin[0] = 0).
  // Only AddHessian, AddGradient, AddControlGradient, AddMixedHessian and
  // AddControlHessian serve them (not StoreHessian nor the band). Allocates.
  void SetDynamicTerms(const std::vector<int>& vars, const std::vector<int>& begin);
  int FixedTerms() const { return fixed_terms_; }
  // Bumped by every SetDynamicTerms that changes the pattern.
  int PatternVersion() const { return version_; }

  int NumStates() const { return num_states_; }
  int NumControls() const { return num_controls_; }
  int NumTerms() const { return static_cast<int>(term_begin_.size()) - 1; }
  int TermSize(int term) const { return term_begin_[term + 1] - term_begin_[term]; }
  const int* TermVars(int term) const { return vars_.data() + term_begin_[term]; }
  // True when the term has at least one control variable (enters E_u, E_xu, E_uu).
  bool TouchesControls(int term) const { return touches_controls_[term] != 0; }

  // Full symmetric E_xx pattern (both triangles, compressed, values 0).
  const SparseMatrix& Pattern() const { return pattern_; }
  // h with the pattern's structure (set on first use, then reused); its values to be
  // stored, zeroed first when `clear` (slots no StoreHessian term reaches, e.g. contact).
  double* Values(SparseMatrix* h, bool clear) const {
    const Eigen::Index n = pattern_.rows();
    if (h->rows() != n || h->cols() != n || h->nonZeros() != pattern_.nonZeros() || !h->isCompressed() ||
        (dynamic_ && !SameStructure(*h))) {
      *h = pattern_;
    }
    double* values = h->valuePtr();
    if (clear) std::fill(values, values + pattern_.nonZeros(), 0.0);
    return values;
  }
  // max |i - j| over the fixed terms' pattern: the half-bandwidth of E_xx; -1 (not
  // known) with dynamic terms, whose pairs may couple any two nodes.
  int Bandwidth() const { return dynamic_ ? -1 : bandwidth_; }

  // The Add* functions accumulate (+=) one term's local derivatives. `local_h` is the
  // term's full symmetric local Hessian, column-major with leading dimension `ld`.
  void AddGradient(int term, const double* local_g, double* g) const;
  void AddControlGradient(int term, const double* local_g, double* eu) const;
  // `values` is valuePtr() of a matrix with exactly Pattern()'s structure.
  void AddHessian(int term, const double* local_h, int ld, double* values) const;
  // The same sum without clearing `values` first: the first term (in term order) to
  // reach a slot stores into it, later ones add. Call it for every term, in order
  // 0 .. NumTerms() - 1. 0 + h == h exactly, so the result is AddHessian's on a zeroed
  // matrix to the last bit, without a pass that clears the whole matrix.
  void StoreHessian(int term, const double* local_h, int ld, double* values) const;
  // AddHessian's sum in band storage (linalg/banded_ldlt.h: with half-bandwidth
  // b = Bandwidth(), A(i, j), i >= j, is band[i (b + 1) + j - i + b]), lower triangle
  // only, each entry read from the local Hessian as AddHessian reads it; the band must
  // hold zeros first. Over terms 0 .. NumTerms() - 1 in order it holds Hessian()'s
  // values (0 + h == h exactly; a -0.0 entry may come out as +0.0).
  void AddBandHessian(int term, const double* local_h, int ld, double* band) const;
  // exu: num_states x num_controls, euu: num_controls x num_controls (presized).
  void AddMixedHessian(int term, const double* local_h, int ld, Mat* exu) const;
  void AddControlHessian(int term, const double* local_h, int ld, Mat* euu) const;

 private:
  // Finalize's steps, in order: the symmetric pattern, its bandwidth and which terms touch
  // the controls; the scatter runs (AddHessian); the runs regrouped for StoreHessian.
  void FinalizePattern();
  void FinalizeRuns();
  void FinalizeStoreRuns();
  // The band runs (AddBandHessian), after the pattern and its bandwidth.
  void FinalizeBand();
  // SetDynamicTerms' steps, in order: the new terms' variables replace the old dynamic
  // ones (returns their state entries (column, row), sorted, unique); the base pattern
  // merged with those entries into pattern_, with where each base entry moved; the fixed
  // terms' runs re-indexed and the dynamic terms' runs built.
  std::vector<std::pair<int, int>> ReplaceDynamicVars(const std::vector<int>& vars, const std::vector<int>& begin);
  void MergeDynamicPattern(const std::vector<std::pair<int, int>>& extra, std::vector<int>* outer,
                           std::vector<int>* inner, std::vector<int>* moved);
  void IndexDynamicRuns(const std::vector<int>& outer, const std::vector<int>& inner,
                        const std::vector<int>& moved);
  // h's compressed structure is the pattern's (same size and non-zero count assumed).
  bool SameStructure(const SparseMatrix& h) const;

  int num_states_ = 0;
  int num_controls_ = 0;
  std::vector<int> term_begin_{0};    // term t's variables are vars_[begin[t], begin[t+1])
  std::vector<int> vars_;
  // E_xx scatter table. For each term, runs of local entries (rows i0 .. i0+len-1 of
  // local column j) that land on consecutive valuePtr() positions value .. value+len-1:
  // a node's coordinates are consecutive in both, so a 3D bending term needs 27 runs of 3
  // rather than 81 separate look-ups.
  struct Run {
    int local_row;
    int local_col;
    int len;
    int value;
    bool first;  // the first term to reach these slots (StoreHessian stores, not adds)
  };
  std::vector<int> run_begin_;        // term t's runs are runs_[run_begin_[t], run_begin_[t+1])
  std::vector<Run> runs_;
  // The same runs for StoreHessian, grouped per term into four loops without branches:
  // first-reached runs of 3, other runs of 3, first-reached others, other others
  // (store_begin_[4 t + k] .. store_begin_[4 t + k + 1]). A slot appears once per term,
  // so the order of the runs within a term does not change any sum.
  std::vector<int> store_begin_;
  std::vector<Run> store_runs_;
  // AddBandHessian's runs for terms whose variables are not consecutive states: local
  // entries (i, j0 .. j0+len-1) of one local row, read with stride ld (column-major),
  // to band slots value .. value+len-1 (one band row); term t's are
  // band_runs_[band_begin_[t], band_begin_[t+1]).
  std::vector<int> band_begin_;
  std::vector<Run> band_runs_;
  // For each term: its first variable v0 when its variables are the states v0, v0 + 1,
  // ..., v0 + k - 1 (k = 4, 6 or 9: the chains' stretching and bending terms), else -1.
  std::vector<int> contiguous_;
  std::vector<char> touches_controls_;
  SparseMatrix pattern_;
  int bandwidth_ = 0;
  // Dynamic terms: the fixed terms' pattern and runs (values indexing base_pattern_),
  // re-indexed into pattern_ by each SetDynamicTerms.
  bool dynamic_ = false;
  int fixed_terms_ = 0;
  int version_ = 0;
  SparseMatrix base_pattern_;
  std::vector<Run> base_runs_, base_store_runs_;
};

}  // namespace snapthread::internal
