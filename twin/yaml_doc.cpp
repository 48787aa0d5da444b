#include "twin/yaml_doc.hpp"

#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

namespace driftless::twin {
namespace {

std::size_t line_of(const YAML::Node& n) {
  const YAML::Mark m = n.Mark();
  return m.is_null() ? 0 : static_cast<std::size_t>(m.line) + 1;
}

fields::Node convert(const YAML::Node& y) {
  fields::Node n;
  n.line = line_of(y);
  switch (y.Type()) {
    case YAML::NodeType::Scalar:
      n.kind = fields::Node::Kind::kScalar;
      n.text = y.Scalar();
      n.quoted = y.Tag() == "!";  // yaml-cpp tags quoted scalars "!"
      break;
    case YAML::NodeType::Sequence:
      n.kind = fields::Node::Kind::kList;
      n.flow = y.Style() == YAML::EmitterStyle::Flow;
      for (const auto& x : y) n.items.push_back(convert(x));
      break;
    case YAML::NodeType::Map:
      n.kind = fields::Node::Kind::kMap;
      n.flow = y.Style() == YAML::EmitterStyle::Flow;
      for (const auto& kv : y) {
        // a key is text; a complex key (a list or map as key) is refused by the tables as unknown
        const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "?";
        n.entries.push_back(fields::Entry{key, line_of(kv.first), convert(kv.second)});
      }
      break;
    default:
      break;  // null or undefined
  }
  return n;
}

}  // namespace

fields::Node parse_yaml(const std::string& text, const std::string& file) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(file, e.mark.is_null() ? 0 : static_cast<std::size_t>(e.mark.line) + 1, "",
                     "broken YAML: " + e.msg);
  }
  fields::Node n = convert(root);
  fields::check_unique_keys(n, file);
  return n;
}

std::string read_yaml_text(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path.string(), 0, "", "is a directory, expected a YAML file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), 0, "", "cannot read (no such file or no permission)");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

fields::Node load_yaml_file(const std::filesystem::path& path) { return parse_yaml(read_yaml_text(path), path.string()); }

void emit_yaml(YAML::Emitter& out, const fields::Node& n) {
  using K = fields::Node::Kind;
  switch (n.kind) {
    case K::kNull: out << YAML::Null; break;
    case K::kScalar:
      if (n.quoted) out << YAML::DoubleQuoted;
      out << n.text;
      break;
    case K::kList:
      if (n.flow) out << YAML::Flow;
      out << YAML::BeginSeq;
      for (const auto& x : n.items) emit_yaml(out, x);
      out << YAML::EndSeq;
      break;
    case K::kMap:
      if (n.flow) out << YAML::Flow;
      out << YAML::BeginMap;
      for (const auto& e : n.entries) {
        out << YAML::Key << e.key << YAML::Value;
        emit_yaml(out, e.value);
      }
      out << YAML::EndMap;
      break;
  }
}

std::string to_yaml(const fields::Node& node, const std::string& comment) {
  YAML::Emitter out;
  if (!comment.empty()) out << YAML::Comment(comment);
  emit_yaml(out, node);
  return out.c_str();
}

}  // namespace driftless::twin
