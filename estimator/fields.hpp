// One field-description mechanism for every configuration block (scenario, motion, box, motor,
// sensor, estimator config, calibration files, sweeps): a block is a list of rows, and that one
// list drives parsing, the allowed keys, unit handling and emitting. Errors are InputErrors naming
// file, line and the dotted key. Standard library and Eigen only: the file formats (YAML in
// twin/yaml_doc.hpp, the flat `key: value` estimator config here) turn text into a Node tree.
//
//   const fields::Table<MotorParams>& motor_table() {
//     static const fields::Table<MotorParams> t = {
//         fields::number("max_speed", "dps", &MotorParams::max_speed_dps), ...};
//     return t;
//   }
//   fields::read_block(motor_table(), motor, node, ctx);   // parse + allowed keys + units
//   fields::Node n = fields::write_block(motor_table(), motor);  // emit, every value explicit
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <iosfwd>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "estimator/input_error.hpp"
#include "estimator/numbers.hpp"
#include "estimator/units.hpp"

namespace driftless::fields {

struct Entry;

/// One node of a parsed configuration document, with the 1-based line it starts on (0: made in
/// code). Scalars keep their text; a map keeps its keys in file order.
struct Node {
  enum class Kind { kNull, kScalar, kList, kMap };
  Kind kind = Kind::kNull;
  std::string text;             // kScalar
  std::vector<Node> items;      // kList
  std::vector<Entry> entries;   // kMap
  std::size_t line = 0;
  bool flow = false;    // emit hint: a list or map on one line ([a, b], {k: v})
  bool quoted = false;  // emit hint: a scalar in double quotes

  static Node scalar(std::string text, bool quoted = false);
  static Node list(std::vector<Node> items, bool flow = true);
  static Node map(bool flow = false);
  /// A null node that only carries a line (to point an error at a key).
  static Node at_line(std::size_t line);
  bool is_null() const { return kind == Kind::kNull; }
  bool is_scalar() const { return kind == Kind::kScalar; }
  bool is_list() const { return kind == Kind::kList; }
  bool is_map() const { return kind == Kind::kMap; }
  /// The value under `key` in a map, or nullptr.
  const Node* find(std::string_view key) const;
  /// Appends `key: value` to a map.
  Node& add(std::string key, Node value);
};

/// A map entry: the key, the line the key is on, the value.
struct Entry {
  std::string key;
  std::size_t line = 0;
  Node value;
};

/// Throws InputError when a map anywhere in `root` holds a key twice (naming both lines). YAML
/// readers otherwise keep one of them silently.
void check_unique_keys(const Node& root, const std::string& file, const std::string& path = {});

/// Where a block is read: the file and the dotted path of the block ("model.box").
struct Context {
  std::string file;
  std::string path;
  /// The dotted key of `key` inside this block.
  std::string key(std::string_view key) const;
  /// The context of the sub-block `key`.
  Context child(std::string_view key) const { return {file, this->key(key)}; }
  /// Throws InputError(file, at.line, key, detail).
  [[noreturn]] void fail(const Node& at, const std::string& key, const std::string& detail) const;
};

/// What a row's reader gets besides the value: where it is and the unit the key was written in.
struct Reading {
  Context ctx;                       // ctx.path is the full dotted key of this value
  double scale = 1.0;                // value in the key's unit * scale = value in the field's unit
  const units::Unit* unit = nullptr; // the unit the key carries (nullptr: none)
  [[noreturn]] void fail(const Node& at, const std::string& detail) const { ctx.fail(at, ctx.path, detail); }
};

// ---- scalar readers (public for blocks with a shape of their own) ----

/// A number; the scalar may carry the key's unit after it ("600 s"). Finite only. Times scale.
double read_number(const Node& n, const Reading& r);
/// true/false (also yes/no, on/off, 1/0).
bool read_bool(const Node& n, const Reading& r);
/// A whole number in [lo, hi].
std::int64_t read_integer(const Node& n, const Reading& r, std::int64_t lo, std::int64_t hi);
/// Any scalar text.
std::string read_text(const Node& n, const Reading& r);

/// One row of a block: the key (stem + canonical unit suffix), how to read and write its value.
template <class T>
struct Row {
  std::string stem;  // "end_stop"
  std::string unit;  // canonical unit suffix, "" for none: the key is "end_stop_deg"
  std::function<void(T&, const Node&, const Reading&)> read;
  std::function<std::optional<Node>(const T&)> write;  // nullopt: the key is left out
  std::string key() const { return unit.empty() ? stem : stem + "_" + unit; }
};

/// A block: its rows in emit order.
template <class T>
using Table = std::vector<Row<T>>;

/// The stems and units of a table, for key resolution (independent of T).
struct KeySpec {
  std::string stem;
  std::string unit;
};

/// Resolves `key` against the rows: which row, and the scale from the key's unit to the row's.
/// Accepts the canonical key and the same stem in another unit of the same quantity
/// ("tau_h" for "tau_s"); throws InputError for a wrong quantity, a missing unit, an unknown key.
struct Resolved {
  std::size_t row = 0;
  double scale = 1.0;
  const units::Unit* unit = nullptr;
};
Resolved resolve_key(const std::vector<KeySpec>& specs, const std::string& key, const Context& ctx,
                     const Node& at, std::initializer_list<std::string_view> extra = {});

template <class T>
std::vector<KeySpec> key_specs(const Table<T>& rows) {
  std::vector<KeySpec> s;
  s.reserve(rows.size());
  for (const auto& r : rows) s.push_back({r.stem, r.unit});
  return s;
}

/// Reads one `key: value` of a block into obj.
template <class T>
void read_key(const Table<T>& rows, T& obj, const std::string& key, const Node& value, const Context& ctx,
              const Node& key_at) {
  const Resolved res = resolve_key(key_specs(rows), key, ctx, key_at);
  rows[res.row].read(obj, value, Reading{ctx.child(key), res.scale, res.unit});
}

/// Reads a map into obj: every key must be a row's (or one of `extra`, which the caller handles).
/// Returns which rows the map gave (by row index), for `require`.
template <class T>
std::vector<bool> read_block(const Table<T>& rows, T& obj, const Node& map, const Context& ctx,
                             std::initializer_list<std::string_view> extra = {}) {
  if (!map.is_map()) ctx.fail(map, ctx.path, "expected a mapping (key: value lines)");
  const auto specs = key_specs(rows);
  std::vector<bool> given(rows.size(), false);
  for (const auto& e : map.entries) {
    bool skip = false;
    for (auto x : extra) skip = skip || e.key == x;
    if (skip) continue;
    const Resolved res = resolve_key(specs, e.key, ctx, Node::at_line(e.line), extra);
    rows[res.row].read(obj, e.value, Reading{ctx.child(e.key), res.scale, res.unit});
    given[res.row] = true;
  }
  return given;
}

/// Throws InputError "missing" naming the first row of `keys` (canonical keys) that `given`
/// (read_block's answer) does not hold; `map` points the error at the block's line.
template <class T>
void require(const Table<T>& rows, const std::vector<bool>& given, const Node& map, const Context& ctx,
             const std::vector<std::string>& keys) {
  for (const auto& k : keys) {
    for (std::size_t i = 0; i < rows.size(); ++i) {
      if (rows[i].key() == k && !(i < given.size() && given[i])) {
        ctx.fail(map, ctx.key(k), "missing (this block needs " + k + ")");
      }
    }
  }
}

/// Writes every row of obj into `map` (appending), in table order.
template <class T>
void write_into(const Table<T>& rows, const T& obj, Node& map) {
  for (const auto& r : rows) {
    if (auto n = r.write(obj)) map.add(r.key(), std::move(*n));
  }
}

/// obj as a map, every row explicit.
template <class T>
Node write_block(const Table<T>& rows, const T& obj, bool flow = false) {
  Node m = Node::map(flow);
  write_into(rows, obj, m);
  return m;
}

/// The keys of a table ("a, b_s, c_deg"), for messages and docs.
template <class T>
std::string key_list(const Table<T>& rows) {
  std::string s;
  for (const auto& r : rows) s += (s.empty() ? "" : ", ") + r.key();
  return s;
}

// ---- row factories. `acc` is a pointer to member or a callable returning a reference to the
//      field (write it generic, `[](auto& t) -> auto& { return t.a.b; }`, so it serves const too).

namespace detail {
template <class T, class Acc>
decltype(auto) at(Acc& acc, T& obj) {
  return std::invoke(acc, obj);
}
Node number_node(double v);
Eigen::MatrixXd read_matrix(const Node& n, const Reading& r, int rows, int cols, bool broadcast);
Node matrix_node(const Eigen::MatrixXd& m, bool flow_rows, bool flow);
}  // namespace detail

/// A number in `unit` (a key suffix of the unit table, "" for none).
template <class T, class Acc>
Row<T> number(std::string stem, std::string unit, Acc acc) {
  return {std::move(stem), std::move(unit),
          [acc](T& o, const Node& n, const Reading& r) mutable { detail::at(acc, o) = read_number(n, r); },
          [acc](const T& o) mutable -> std::optional<Node> { return detail::number_node(detail::at(acc, o)); }};
}

/// A whole number in [lo, hi] of any integer type.
template <class T, class Acc>
Row<T> integer(std::string stem, Acc acc, std::int64_t lo, std::int64_t hi) {
  return {std::move(stem), "",
          [acc, lo, hi](T& o, const Node& n, const Reading& r) mutable {
            auto& f = detail::at(acc, o);
            f = static_cast<std::remove_reference_t<decltype(f)>>(read_integer(n, r, lo, hi));
          },
          [acc](const T& o) mutable -> std::optional<Node> {
            return Node::scalar(std::to_string(detail::at(acc, o)));
          }};
}

/// true/false.
template <class T, class Acc>
Row<T> flag(std::string stem, Acc acc) {
  return {std::move(stem), "",
          [acc](T& o, const Node& n, const Reading& r) mutable { detail::at(acc, o) = read_bool(n, r); },
          [acc](const T& o) mutable -> std::optional<Node> {
            return Node::scalar(detail::at(acc, o) ? "true" : "false");
          }};
}

/// Text; `quoted` writes it in double quotes; `omit_empty` leaves an empty text out.
template <class T, class Acc>
Row<T> text(std::string stem, Acc acc, bool quoted = false, bool omit_empty = false) {
  return {std::move(stem), "",
          [acc](T& o, const Node& n, const Reading& r) mutable { detail::at(acc, o) = read_text(n, r); },
          [acc, quoted, omit_empty](const T& o) mutable -> std::optional<Node> {
            const std::string& s = detail::at(acc, o);
            if (omit_empty && s.empty()) return std::nullopt;
            return Node::scalar(s, quoted);
          }};
}

/// A fixed-size Eigen vector [x, y, ...] in `unit`; `broadcast` also takes one number for all.
template <class T, class Acc>
Row<T> vector(std::string stem, std::string unit, Acc acc, bool broadcast = false) {
  return {std::move(stem), std::move(unit),
          [acc, broadcast](T& o, const Node& n, const Reading& r) mutable {
            auto& v = detail::at(acc, o);
            v = detail::read_matrix(n, r, static_cast<int>(v.size()), 1, broadcast);
          },
          [acc](const T& o) mutable -> std::optional<Node> {
            return detail::matrix_node(detail::at(acc, o), true, true);
          }};
}

/// A 3x3 matrix as three rows [[a, b, c], [d, e, f], [g, h, i]] (or nine numbers) in `unit`;
/// written on one line when `flow`, else one row per line.
template <class T, class Acc>
Row<T> matrix3(std::string stem, std::string unit, Acc acc, bool flow = true) {
  return {std::move(stem), std::move(unit),
          [acc](T& o, const Node& n, const Reading& r) mutable {
            detail::at(acc, o) = detail::read_matrix(n, r, 3, 3, false);
          },
          [acc, flow](const T& o) mutable -> std::optional<Node> {
            return detail::matrix_node(detail::at(acc, o), true, flow);
          }};
}

/// A list of whole numbers in [lo, hi].
template <class T, class Acc>
Row<T> integer_list(std::string stem, Acc acc, std::int64_t lo, std::int64_t hi) {
  return {std::move(stem), "",
          [acc, lo, hi](T& o, const Node& n, const Reading& r) mutable {
            if (!n.is_list()) r.fail(n, "expected a list of whole numbers");
            auto& v = detail::at(acc, o);
            v.clear();
            for (const auto& x : n.items) v.push_back(static_cast<int>(read_integer(x, r, lo, hi)));
          },
          [acc](const T& o) mutable -> std::optional<Node> {
            std::vector<Node> items;
            for (auto c : detail::at(acc, o)) items.push_back(Node::scalar(std::to_string(c)));
            return Node::list(std::move(items));
          }};
}

/// A list of text values [a, b, c].
template <class T, class Acc>
Row<T> text_list(std::string stem, Acc acc) {
  return {std::move(stem), "",
          [acc](T& o, const Node& n, const Reading& r) mutable {
            if (!n.is_list()) r.fail(n, "expected a list [a, b, ...]");
            auto& v = detail::at(acc, o);
            v.clear();
            for (const auto& x : n.items) v.push_back(read_text(x, r));
          },
          [acc](const T& o) mutable -> std::optional<Node> {
            std::vector<Node> items;
            for (const auto& x : detail::at(acc, o)) items.push_back(Node::scalar(x));
            return Node::list(std::move(items));
          }};
}

/// An enumeration written as a name: `names` lists {name, value} pairs.
template <class E>
using Names = std::vector<std::pair<std::string, E>>;

template <class E>
E read_choice(const Node& n, const Reading& r, const Names<E>& names) {
  const std::string v = read_text(n, r);
  for (const auto& [name, e] : names) {
    if (name == v) return e;
  }
  std::string list;
  for (const auto& [name, e] : names) list += (list.empty() ? "" : ", ") + name;
  r.fail(n, "expected one of " + list + ", got '" + v + "'");
}

template <class E>
const std::string& choice_name(E e, const Names<E>& names) {
  for (const auto& [name, v] : names) {
    if (v == e) return name;
  }
  return names.front().first;
}

template <class T, class Acc, class E>
Row<T> choice(std::string stem, Acc acc, Names<E> names) {
  return {std::move(stem), "",
          [acc, names](T& o, const Node& n, const Reading& r) mutable { detail::at(acc, o) = read_choice(n, r, names); },
          [acc, names](const T& o) mutable -> std::optional<Node> {
            return Node::scalar(choice_name<E>(detail::at(acc, o), names));
          }};
}

/// A nested block read and written through its own table; `required` lists the keys it must give.
template <class T, class Acc, class S>
Row<T> block(std::string stem, Acc acc, const Table<S>& (*table)(), std::vector<std::string> required = {}) {
  return {std::move(stem), "",
          [acc, table, required](T& o, const Node& n, const Reading& r) mutable {
            const auto given = read_block(table(), detail::at(acc, o), n, r.ctx);
            require(table(), given, n, r.ctx, required);
          },
          [acc, table](const T& o) mutable -> std::optional<Node> { return write_block(table(), detail::at(acc, o)); }};
}

/// A list of blocks [{...}, {...}], each read through `table` into a fresh S; written one item a
/// line, each item a flow map.
template <class T, class Acc, class S>
Row<T> block_list(std::string stem, Acc acc, const Table<S>& (*table)()) {
  return {std::move(stem), "",
          [acc, table](T& o, const Node& n, const Reading& r) mutable {
            if (!n.is_list()) r.fail(n, "expected a list of blocks ({key: value, ...} items)");
            auto& v = detail::at(acc, o);
            v.clear();
            for (std::size_t i = 0; i < n.items.size(); ++i) {
              v.emplace_back();
              read_block(table(), v.back(), n.items[i], Context{r.ctx.file, r.ctx.path + "[" + std::to_string(i) + "]"});
            }
          },
          [acc, table](const T& o) mutable -> std::optional<Node> {
            std::vector<Node> items;
            for (const auto& x : detail::at(acc, o)) items.push_back(write_block(table(), x, true));
            return Node::list(std::move(items), false);
          }};
}

/// A number that may be `null` (read as NaN; NaN is written as null): a value not known.
template <class T, class Acc>
Row<T> number_or_null(std::string stem, std::string unit, Acc acc) {
  return {std::move(stem), std::move(unit),
          [acc](T& o, const Node& n, const Reading& r) mutable {
            detail::at(acc, o) = n.is_null() ? std::numeric_limits<double>::quiet_NaN() : read_number(n, r);
          },
          [acc](const T& o) mutable -> std::optional<Node> {
            const double v = detail::at(acc, o);
            return std::isfinite(v) ? detail::number_node(v) : Node{};
          }};
}

/// An optional row: reading it sets the flag `has`, and it is written only when the flag is set.
/// Rows that are always given together may share one flag.
template <class T, class Flag>
Row<T> optional_row(Row<T> row, Flag has) {
  auto read = row.read;
  auto write = row.write;
  row.read = [read, has](T& o, const Node& n, const Reading& r) mutable {
    read(o, n, r);
    detail::at(has, o) = true;
  };
  row.write = [write, has](const T& o) mutable -> std::optional<Node> {
    if (!detail::at(has, o)) return std::nullopt;
    return write(o);
  };
  return row;
}

/// A row written only when `when(obj)` holds (read as usual).
template <class T>
Row<T> written_if(Row<T> row, std::function<bool(const T&)> when) {
  auto write = row.write;
  row.write = [write, when](const T& o) -> std::optional<Node> {
    if (!when(o)) return std::nullopt;
    return write(o);
  };
  return row;
}

/// A row with its own reader and writer (a block of a shape the factories do not cover).
template <class T>
Row<T> custom(std::string stem, std::string unit, std::function<void(T&, const Node&, const Reading&)> read,
              std::function<std::optional<Node>(const T&)> write) {
  return {std::move(stem), std::move(unit), std::move(read), std::move(write)};
}

// ---- the flat `key: value` form (the estimator config): a YAML subset, one scalar per line ----

/// Reads `key: value` lines ('#' comments, blank lines, '---' ignored; "quoted" values unquoted)
/// into a map; throws InputError on a line that is not `key: value` or a key given twice.
Node read_flat(std::istream& in, const std::string& file);
/// Writes a map of scalars as `key: value` lines.
void write_flat(std::ostream& out, const Node& map);

}  // namespace driftless::fields
