#include "tools/dataset/text_lines.hpp"

#include <charconv>
#include <cmath>
#include <fstream>

#include "tools/dataset/input_error.hpp"

namespace parallax {

void ForEachDataLine(const std::string& path,
                     const std::function<void(const std::string&, int)>& fn) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open file");
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    fn(line, line_number);
  }
}

std::vector<std::string> SplitFields(const std::string& line) {
  std::vector<std::string> fields;
  std::string current;
  for (const char c : line) {
    if (c == ' ' || c == '\t' || c == ',') {
      if (!current.empty()) fields.push_back(std::move(current));
      current.clear();
    } else {
      current += c;
    }
  }
  if (!current.empty()) fields.push_back(std::move(current));
  return fields;
}

int ToImageDimension(double value, const std::string& path, int line_number,
                     const std::string& what) {
  if (!(value >= 1.0 && value <= 65536.0 && value == std::floor(value))) {
    throw InputError(
        path, line_number,
        what + " must be a whole number of pixels in [1, 65536], got " + std::to_string(value));
  }
  return static_cast<int>(value);
}

double ParseDouble(const std::string& text, const std::string& path, int line_number,
                   const std::string& what) {
  double value = 0.0;
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  if (ec != std::errc() || ptr != end || !std::isfinite(value)) {
    throw InputError(path, line_number, what + " '" + text + "' is not a finite number");
  }
  return value;
}

std::vector<double> ParseNumbers(const std::string& line, const std::string& path, int line_number,
                                 std::size_t count, bool allow_more) {
  const std::vector<std::string> fields = SplitFields(line);
  if (fields.size() < count || (!allow_more && fields.size() != count)) {
    throw InputError(path, line_number,
                     "expected " + std::to_string(count) + " numbers, found " +
                         std::to_string(fields.size()) + " fields");
  }
  std::vector<double> values;
  values.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    values.push_back(ParseDouble(fields[i], path, line_number, "field " + std::to_string(i + 1)));
  }
  return values;
}

}  // namespace parallax
