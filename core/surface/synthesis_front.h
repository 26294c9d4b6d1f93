// The order in which local-patch synthesis visits the base (paper section 3.1, as the planar
// synthesis of section 2.3 grows from what is synthesised): the next seed is a face not yet
// synthesised with the most synthesised neighbours, ties to the lowest index.
#pragma once

#include <set>
#include <utility>
#include <vector>

#include "core/mesh/mesh.h"

namespace mq {

class SynthesisFront {
 public:
  // TT: #F by 3 face adjacency (-1 where a face has no neighbour); must outlive the front.
  explicit SynthesisFront(const MatrixX3i& TT);

  bool empty() const { return queue_.empty(); }
  // The next seed. Precondition: !empty().
  int next() const { return queue_.begin()->second; }
  // Marks face f synthesised (again: no effect); its neighbours move up the queue.
  void mark(int f);
  bool synthesised(int f) const { return synthesised_[static_cast<size_t>(f)] != 0; }
  int num_synthesised() const { return num_synthesised_; }

 private:
  const MatrixX3i& TT_;
  std::vector<unsigned char> synthesised_;
  std::vector<int> count_;               // per face: synthesised neighbours
  std::set<std::pair<int, int>> queue_;  // (-synthesised neighbours, face)
  int num_synthesised_ = 0;
};

}  // namespace mq
