#include "estimator/fields.hpp"

#include <charconv>
#include <cmath>
#include <istream>
#include <map>
#include <ostream>

namespace driftless::fields {
namespace {

std::string trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return std::string(s.substr(b, e - b + 1));
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  return s;
}

// the row whose stem prefixes `key` with "_<a known unit>", longest stem first
std::optional<Resolved> by_unit_suffix(const std::vector<KeySpec>& specs, const std::string& key) {
  std::optional<Resolved> best;
  std::size_t best_len = 0;
  for (std::size_t i = 0; i < specs.size(); ++i) {
    const std::string& stem = specs[i].stem;
    if (key.size() <= stem.size() + 1 || key.compare(0, stem.size(), stem) != 0 || key[stem.size()] != '_') continue;
    const units::Unit* u = units::find(std::string_view(key).substr(stem.size() + 1));
    if (u != nullptr && (!best || stem.size() > best_len)) {
      best = Resolved{i, 1.0, u};
      best_len = stem.size();
    }
  }
  return best;
}

std::string allowed_list(const std::vector<KeySpec>& specs, std::initializer_list<std::string_view> extra) {
  std::string s;
  for (auto x : extra) s += (s.empty() ? "" : ", ") + std::string(x);
  for (const auto& k : specs) s += (s.empty() ? "" : ", ") + (k.unit.empty() ? k.stem : k.stem + "_" + k.unit);
  return s;
}

}  // namespace

// ---- Node ----

Node Node::scalar(std::string text, bool quoted) {
  Node n;
  n.kind = Kind::kScalar;
  n.text = std::move(text);
  n.quoted = quoted;
  return n;
}

Node Node::list(std::vector<Node> items, bool flow) {
  Node n;
  n.kind = Kind::kList;
  n.items = std::move(items);
  n.flow = flow;
  return n;
}

Node Node::map(bool flow) {
  Node n;
  n.kind = Kind::kMap;
  n.flow = flow;
  return n;
}

Node Node::at_line(std::size_t line) {
  Node n;
  n.line = line;
  return n;
}

const Node* Node::find(std::string_view key) const {
  for (const auto& e : entries) {
    if (e.key == key) return &e.value;
  }
  return nullptr;
}

Node& Node::add(std::string key, Node value) {
  entries.push_back(Entry{std::move(key), 0, std::move(value)});
  return entries.back().value;
}

void check_unique_keys(const Node& root, const std::string& file, const std::string& path) {
  const auto dotted = [&](const std::string& k) { return path.empty() ? k : path + "." + k; };
  if (root.is_list()) {
    for (std::size_t i = 0; i < root.items.size(); ++i)
      check_unique_keys(root.items[i], file, path + "[" + std::to_string(i) + "]");
  }
  if (!root.is_map()) return;
  std::map<std::string, std::size_t> first_line;
  for (const auto& e : root.entries) {
    const auto [it, fresh] = first_line.emplace(e.key, e.line);
    if (!fresh) {
      throw InputError(file, e.line, dotted(e.key),
                       "key given twice (lines " + std::to_string(it->second) + " and " + std::to_string(e.line) +
                           "); keep one");
    }
    check_unique_keys(e.value, file, dotted(e.key));
  }
}

// ---- Context ----

std::string Context::key(std::string_view k) const { return path.empty() ? std::string(k) : path + "." + std::string(k); }

void Context::fail(const Node& at, const std::string& key, const std::string& detail) const {
  throw InputError(file, at.line, key, detail);
}

// ---- key resolution ----

Resolved resolve_key(const std::vector<KeySpec>& specs, const std::string& key, const Context& ctx, const Node& at,
                     std::initializer_list<std::string_view> extra) {
  for (std::size_t i = 0; i < specs.size(); ++i) {
    const auto& s = specs[i];
    if ((s.unit.empty() ? s.stem : s.stem + "_" + s.unit) == key) return {i, 1.0, units::find(s.unit)};
  }
  const std::string full = ctx.key(key);
  if (auto r = by_unit_suffix(specs, key)) {
    const KeySpec& s = specs[r->row];
    const units::Unit* want = units::find(s.unit);
    const std::string canonical = s.unit.empty() ? s.stem : s.stem + "_" + s.unit;
    if (want == nullptr) {
      ctx.fail(at, full, "inconsistent units: '" + key + "' carries a unit but this field has none; write '" +
                             canonical + "'");
    }
    if (want->quantity != r->unit->quantity) {
      ctx.fail(at, full, "inconsistent units: '" + key + "' is in " + std::string(units::label(*r->unit)) +
                             " but this field is in " + std::string(units::label(*want)) + " (one of: " +
                             units::list_of(want->quantity) + "); write '" + canonical + "' with the value converted");
    }
    r->scale = units::factor(*r->unit, *want);
    return *r;
  }
  for (const auto& s : specs) {
    if (!s.unit.empty() && s.stem == key) {
      ctx.fail(at, full, "this value needs its unit in the key: write '" + s.stem + "_" + s.unit + "'");
    }
  }
  ctx.fail(at, full, "unknown key (allowed here: " + allowed_list(specs, extra) + ")");
}

// ---- scalar readers ----

double read_number(const Node& n, const Reading& r) {
  if (!n.is_scalar()) r.fail(n, "expected a number");
  const std::string& text = n.text;
  const std::string l = lower(text);
  if (l == ".inf" || l == "-.inf" || l == "+.inf" || l == ".nan" || l == "inf" || l == "-inf" || l == "nan")
    r.fail(n, "expected a finite number, got '" + text + "'");
  const char* b = text.data();
  const char* e = text.data() + text.size();
  if (b != e && *b == '+') ++b;
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(b, e, v);
  const std::string hint = r.unit ? " in " + std::string(units::label(*r.unit)) : "";
  if (ec != std::errc() || ptr == b) r.fail(n, "expected a number" + hint + ", got '" + text + "'");
  const std::string rest = trim(std::string_view(ptr, static_cast<std::size_t>(e - ptr)));
  if (!rest.empty()) {
    bool ok = false;
    if (r.unit) {
      for (auto sp : r.unit->spellings) ok = ok || rest == sp;
    }
    if (!ok) {
      r.fail(n, "inconsistent units: value '" + text + "' carries unit '" + rest + "' but this field is" +
                    (r.unit ? " in " + std::string(units::label(*r.unit)) : " dimensionless"));
    }
  }
  if (!std::isfinite(v)) r.fail(n, "expected a finite number, got '" + text + "'");
  return r.scale == 1.0 ? v : v * r.scale;
}

bool read_bool(const Node& n, const Reading& r) {
  if (n.is_scalar()) {
    const std::string l = lower(n.text);
    if (l == "true" || l == "yes" || l == "on" || l == "1") return true;
    if (l == "false" || l == "no" || l == "off" || l == "0") return false;
  }
  r.fail(n, "expected true or false" + (n.is_scalar() ? ", got '" + n.text + "'" : std::string()));
}

std::int64_t read_integer(const Node& n, const Reading& r, std::int64_t lo, std::int64_t hi) {
  Reading plain = r;
  plain.scale = 1.0;
  const double v = read_number(n, plain);
  if (v != std::floor(v) || v < static_cast<double>(lo) || v > static_cast<double>(hi)) {
    r.fail(n, "expected a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got '" + n.text +
                  "'");
  }
  return static_cast<std::int64_t>(v);
}

std::string read_text(const Node& n, const Reading& r) {
  if (!n.is_scalar()) r.fail(n, "expected a text value");
  return n.text;
}

// ---- numbers, vectors and matrices ----

namespace detail {

Node number_node(double v) { return Node::scalar(exact_number(v)); }

Eigen::MatrixXd read_matrix(const Node& n, const Reading& r, int rows, int cols, bool broadcast) {
  Eigen::MatrixXd m(rows, cols);
  const auto count = static_cast<std::size_t>(rows * cols);
  if (cols == 1) {
    if (broadcast && n.is_scalar()) return Eigen::VectorXd::Constant(rows, read_number(n, r));
    if (!n.is_list() || n.items.size() != count) {
      r.fail(n, broadcast ? "expected a number (all axes) or a list [x, y, z]"
                          : "expected a list of " + std::to_string(rows) + " numbers, e.g. [" +
                                std::string(rows == 3 ? "0, 0, 1" : "0, 0") + "]");
    }
    for (int i = 0; i < rows; ++i) m(i, 0) = read_number(n.items[static_cast<std::size_t>(i)], r);
    return m;
  }
  const char* shape = "expected a 3x3 matrix: [[a, b, c], [d, e, f], [g, h, i]] (rows)";
  if (n.is_list() && n.items.size() == count) {  // all numbers in a row
    for (std::size_t i = 0; i < count; ++i) m(static_cast<int>(i) / cols, static_cast<int>(i) % cols) = read_number(n.items[i], r);
    return m;
  }
  if (!n.is_list() || n.items.size() != static_cast<std::size_t>(rows)) r.fail(n, shape);
  for (int i = 0; i < rows; ++i) {
    const Node& row = n.items[static_cast<std::size_t>(i)];
    if (!row.is_list() || row.items.size() != static_cast<std::size_t>(cols)) r.fail(row, shape);
    for (int j = 0; j < cols; ++j) m(i, j) = read_number(row.items[static_cast<std::size_t>(j)], r);
  }
  return m;
}

Node matrix_node(const Eigen::MatrixXd& m, bool flow_rows, bool flow) {
  const auto row_node = [&](Eigen::Index i) {
    std::vector<Node> xs;
    for (Eigen::Index j = 0; j < m.cols(); ++j) xs.push_back(number_node(m(i, j)));
    return Node::list(std::move(xs), flow_rows);
  };
  if (m.cols() == 1) {
    std::vector<Node> xs;
    for (Eigen::Index i = 0; i < m.rows(); ++i) xs.push_back(number_node(m(i, 0)));
    return Node::list(std::move(xs), flow);
  }
  std::vector<Node> rows;
  for (Eigen::Index i = 0; i < m.rows(); ++i) rows.push_back(row_node(i));
  return Node::list(std::move(rows), flow);
}

}  // namespace detail

// ---- the flat form ----

Node read_flat(std::istream& in, const std::string& file) {
  Node map = Node::map();
  map.line = 1;
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    line = trim(line);
    if (line.empty() || line == "---") continue;
    const auto colon = line.find(':');
    if (colon == std::string::npos) throw InputError(file, line_no, "", "expected 'key: value', got '" + line + "'");
    std::string value = trim(std::string_view(line).substr(colon + 1));
    if (value.size() >= 2 && (value.front() == '"' || value.front() == '\'') && value.back() == value.front()) {
      value = value.substr(1, value.size() - 2);
    }
    Node v = Node::scalar(value);
    v.line = line_no;
    map.entries.push_back(Entry{trim(std::string_view(line).substr(0, colon)), line_no, std::move(v)});
  }
  check_unique_keys(map, file);
  return map;
}

void write_flat(std::ostream& out, const Node& map) {
  std::string s;
  for (const auto& e : map.entries) s += e.key + ": " + e.value.text + "\n";
  out << s;
}

}  // namespace driftless::fields
