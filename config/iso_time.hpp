// ISO-8601 date-times as historians export them, to seconds since the Unix
// epoch (UTC), for the time column of a recording. Internal to config/.
#pragma once

#include <optional>
#include <string_view>

namespace mpm::config::detail {

// YYYY-MM-DD(T| )hh:mm[:ss[(.|,)fraction]][Z | (+|-)hh[[:]mm]], the whole
// text (already trimmed). Without a zone the time is taken as UTC. Returns
// nullopt for anything else, or an impossible date or time (2026-02-30,
// 24:00, a leap second): a time column is refused rather than guessed.
std::optional<double> parse_iso8601(std::string_view text) noexcept;

// A cheap test before parse_iso8601: digits, '-', digits (a date).
bool looks_like_date(std::string_view text) noexcept;

}  // namespace mpm::config::detail
