// YAML files as fields::Node trees (estimator/fields.hpp): the one place the program reads and
// writes YAML through yaml-cpp. Reading refuses broken YAML and duplicate keys (naming both
// lines) with an InputError; writing keeps the style hints (flow lists, quoted text).
#pragma once

#include <filesystem>
#include <string>

#include "estimator/fields.hpp"

namespace YAML {
class Emitter;
}

namespace driftless::twin {

/// Parses YAML text; `file` names it in errors. An empty document gives a null node.
fields::Node parse_yaml(const std::string& text, const std::string& file);
/// The text of a YAML file (InputError naming the file when it is a directory or cannot be read).
std::string read_yaml_text(const std::filesystem::path& path);
/// Reads and parses a YAML file (InputError when it cannot be read).
fields::Node load_yaml_file(const std::filesystem::path& path);
/// Writes a node into an emitter (inside a map value, a sequence, or at the top).
void emit_yaml(YAML::Emitter& out, const fields::Node& node);
/// The node as YAML text (no trailing newline), after `comment` as '#' lines when not empty.
std::string to_yaml(const fields::Node& node, const std::string& comment = "");

}  // namespace driftless::twin
