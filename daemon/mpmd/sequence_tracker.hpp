// Classifies each sample's (session, sequence) against the last one seen from
// the controller. Publishers number samples 1, 2, 3, ... and may carry a
// random session id that changes when they restart.
//
//   first       the first sample ever
//   next        sequence = last + 1
//   gap         sequence > last + 1: `missing` samples never arrived
//   duplicate   sequence = last: dropped
//   out_of_order sequence < last: dropped (the hole it left was already
//               counted as a gap when the later sample arrived; the monitor
//               cannot go back in time)
//   restart     a new non-zero session id, or the sequence back to 0 or 1:
//               the publisher restarted; tracking starts again from it
//
// Real-time safe: no allocation, no exceptions.
#pragma once

#include <cstdint>

namespace mpm {

class SequenceTracker {
 public:
  enum class Verdict : std::uint8_t { kFirst, kNext, kGap, kDuplicate, kOutOfOrder, kRestart };
  struct Result {
    Verdict verdict;
    std::int64_t missing = 0;  // samples lost, for kGap
  };

  Result observe(std::int64_t session_id, std::int64_t seq) noexcept {
    if (!started_) return accept({Verdict::kFirst}, session_id, seq);
    if (session_id != 0 && session_ != 0 && session_id != session_) return accept({Verdict::kRestart}, session_id, seq);
    if (seq == last_) return {Verdict::kDuplicate};
    if (seq == last_ + 1) return accept({Verdict::kNext}, session_id, seq);
    if (seq > last_) return accept({Verdict::kGap, seq - last_ - 1}, session_id, seq);
    if (seq <= 1) return accept({Verdict::kRestart}, session_id, seq);
    return {Verdict::kOutOfOrder};
  }

  std::int64_t last() const noexcept { return last_; }
  template <class V>
  void visit_state(V&& v) {  // checkpoint
    v(started_); v(session_); v(last_);
  }

 private:
  Result accept(Result r, std::int64_t session_id, std::int64_t seq) noexcept {
    started_ = true;
    session_ = session_id;
    last_ = seq;
    return r;
  }

  bool started_ = false;
  std::int64_t session_ = 0;
  std::int64_t last_ = 0;
};

}  // namespace mpm
