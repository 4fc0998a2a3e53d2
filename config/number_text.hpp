// Text -> number conversion shared by the YAML and CSV readers. Internal to
// config/. std::from_chars is locale-independent (always '.' as decimal point)
// and fast, which matters for million-row recordings.
#pragma once

#include <optional>
#include <string_view>

namespace mpm::config::detail {

// Strips spaces and tabs at both ends.
std::string_view trim(std::string_view text) noexcept;

// Parses the whole of `text` (already trimmed) as a double; accepts a leading
// '+'. Returns nullopt if any character is left over or nothing parses.
// "nan" and "inf" spellings parse (as from_chars does); callers decide.
std::optional<double> parse_double(std::string_view text) noexcept;

// True for "nan", "+nan", "-nan" in any letter case.
bool is_nan_word(std::string_view text) noexcept;

}  // namespace mpm::config::detail
