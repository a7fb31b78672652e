#pragma once
// Precondition checks for public APIs: a violated precondition throws
// std::invalid_argument with a message naming what was wrong (docs/conventions.md, "Errors").

#include <stdexcept>
#include <string>

namespace parallax {

/// Throws std::invalid_argument(message) unless condition holds.
inline void CheckArgument(bool condition, const std::string& message) {
  if (!condition) throw std::invalid_argument(message);
}

/// Throws std::logic_error(message) unless condition holds (a call the object's state does
/// not allow).
inline void CheckState(bool condition, const std::string& message) {
  if (!condition) throw std::logic_error(message);
}

/// Check for one field of an options struct: the message reads "<Struct>.<field> <rule>".
inline void CheckOption(bool condition, const char* struct_name, const char* field,
                        const std::string& rule) {
  if (!condition) {
    throw std::invalid_argument(std::string(struct_name) + "." + field + " " + rule);
  }
}

}  // namespace parallax
