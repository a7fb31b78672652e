#pragma once
// Line-oriented parsing of text data files with file:line error messages.

#include <functional>
#include <string>
#include <vector>

namespace parallax {

/// Calls fn(line, line_number) for every line that is not blank and does not start with '#'
/// (after leading spaces); line numbers start at 1. Throws InputError if the file cannot be
/// opened. Trailing '\r' is removed (files written on Windows).
void ForEachDataLine(const std::string& path,
                     const std::function<void(const std::string&, int)>& fn);

/// Splits on whitespace and commas.
std::vector<std::string> SplitFields(const std::string& line);

/// Parses exactly `count` finite numbers (at least `count` if allow_more) from a line; throws
/// InputError(path, line_number, ...) otherwise.
std::vector<double> ParseNumbers(const std::string& line, const std::string& path, int line_number,
                                 std::size_t count, bool allow_more = false);

/// An image dimension: a whole number of pixels in [1, 65536]; throws InputError naming the
/// field otherwise (a double outside int's range must not reach a cast).
int ToImageDimension(double value, const std::string& path, int line_number,
                     const std::string& what);

/// Parses one finite double; throws InputError naming the field on failure.
double ParseDouble(const std::string& text, const std::string& path, int line_number,
                   const std::string& what);

}  // namespace parallax
