#pragma once
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace misalloc {

// `text` as valid UTF-8: every byte that is not part of a well-formed UTF-8 sequence
// is written as the four characters \xNN. File names are bytes, not text, and a
// report must hold whichever the user gave.
std::string validUtf8(const std::string& text);

// `json` indented by 2 with a final newline, every string and key made valid UTF-8
// first, so that serialising a report never fails.
std::string jsonText(const nlohmann::json& json);

// The value, or null where there is none.
inline nlohmann::json optionalJson(const std::optional<double>& value) {
  return value ? nlohmann::json(*value) : nlohmann::json();
}

}  // namespace misalloc
