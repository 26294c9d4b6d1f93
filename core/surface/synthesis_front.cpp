#include "core/surface/synthesis_front.h"

namespace mq {

SynthesisFront::SynthesisFront(const MatrixX3i& TT)
    : TT_(TT),
      synthesised_(static_cast<size_t>(TT.rows()), 0),
      count_(static_cast<size_t>(TT.rows()), 0) {
  for (int f = 0; f < TT.rows(); ++f) queue_.emplace(0, f);
}

void SynthesisFront::mark(int f) {
  if (synthesised_[f]) return;
  synthesised_[f] = 1;
  ++num_synthesised_;
  queue_.erase({-count_[f], f});
  for (int k = 0; k < 3; ++k) {
    const int g = TT_(f, k);
    if (g < 0 || synthesised_[g]) continue;
    queue_.erase({-count_[g], g});
    ++count_[g];
    queue_.emplace(-count_[g], g);
  }
}

}  // namespace mq
