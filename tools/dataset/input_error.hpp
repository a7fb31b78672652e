#pragma once
// Errors about user-supplied files: the message always names the file (and line when known).

#include <stdexcept>
#include <string>

namespace parallax {

/// Bad or missing input file. what() reads "<file>:<line>: <message>" (or "<file>: ...").
class InputError : public std::runtime_error {
 public:
  InputError(const std::string& file, int line, const std::string& message)
      : std::runtime_error(file + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": " +
                           message),
        file_(file),
        line_(line) {}
  InputError(const std::string& file, const std::string& message) : InputError(file, 0, message) {}

  const std::string& File() const { return file_; }
  int Line() const { return line_; }

 private:
  std::string file_;
  int line_;
};

}  // namespace parallax
