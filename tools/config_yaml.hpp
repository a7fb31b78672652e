#pragma once
// The pipeline configuration file (YAML) mapped onto SystemOptions (docs/configuration.md).

#include <string>

#include "backend/system.hpp"

namespace parallax {

/// Overrides fields of `options` with the keys present in the YAML file `path`; absent keys
/// keep their values. Throws InputError naming file and line for a syntax error, an unknown
/// section or key, a value of the wrong type, or options that fail their Check().
void ApplyConfigYaml(const std::string& path, SystemOptions* options);
/// The same for YAML text (the C API's options); errors name `name` and the line.
void ApplyConfigYamlText(const std::string& text, const std::string& name, SystemOptions* options);

}  // namespace parallax
