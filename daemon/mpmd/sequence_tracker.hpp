// Classifies each sample's (session, sequence) against the last one accepted
// from the controller. Publishers number samples 1, 2, 3, ... and may carry a
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
//   jump        the sequence moved further than `max_jump` either way: not a
//               plausible gap (a corrupt or hostile number, a publisher that
//               renumbered). Tracking resynchronises on it, like a restart,
//               instead of counting 10^15 samples missing or dropping every
//               later sample as out of order for ever (chrony rejects
//               implausible jumps of a source the same way).
//
// Sequence numbers are arbitrary int64 from the wire: differences are taken
// in unsigned arithmetic, so INT64_MIN, INT64_MAX and negative numbers are
// classified without signed overflow, and `missing` is never negative.
//
// Only well-formed samples may be observed: the service checks sizes first,
// so a malformed sample never moves the sequence or the session.
//
// Real-time safe: no allocation, no exceptions.
#pragma once

#include <cstdint>

namespace mpm {

class SequenceTracker {
 public:
  enum class Verdict : std::uint8_t { kFirst, kNext, kGap, kDuplicate, kOutOfOrder, kRestart, kJump };
  struct Result {
    Verdict verdict;
    std::int64_t missing = 0;  // samples lost, for kGap: 1 .. max_jump
  };

  // `max_jump`: the largest gap (and the furthest step back) taken as
  // plausible; at least 1.
  explicit SequenceTracker(std::int64_t max_jump = kDefaultMaxJump) noexcept
      : max_jump_(max_jump < 1 ? 1 : static_cast<std::uint64_t>(max_jump)) {}

  static constexpr std::int64_t kDefaultMaxJump = 1000000;

  Result observe(std::int64_t session_id, std::int64_t seq) noexcept {
    if (!started_) return accept({Verdict::kFirst}, session_id, seq);
    if (session_id != 0 && session_ != 0 && session_id != session_) return accept({Verdict::kRestart}, session_id, seq);
    if (seq == last_) return {Verdict::kDuplicate};
    if (seq > last_) {
      // Exact in uint64 for any two int64 with seq > last.
      const std::uint64_t ahead = static_cast<std::uint64_t>(seq) - static_cast<std::uint64_t>(last_);
      if (ahead == 1) return accept({Verdict::kNext}, session_id, seq);
      if (ahead - 1 > max_jump_) return accept({Verdict::kJump}, session_id, seq);
      return accept({Verdict::kGap, static_cast<std::int64_t>(ahead - 1)}, session_id, seq);
    }
    if (seq <= 1) return accept({Verdict::kRestart}, session_id, seq);
    const std::uint64_t behind = static_cast<std::uint64_t>(last_) - static_cast<std::uint64_t>(seq);
    if (behind > max_jump_) return accept({Verdict::kJump}, session_id, seq);
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

  std::uint64_t max_jump_;
  bool started_ = false;
  std::int64_t session_ = 0;
  std::int64_t last_ = 0;
};

}  // namespace mpm
