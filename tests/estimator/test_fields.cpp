// The one field-description mechanism: a table drives parse, allowed keys, units and emit; errors
// name file, line and the dotted key; duplicate keys are refused naming both lines.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "estimator/fields.hpp"
#include "estimator/sample.hpp"
#include "estimator/units.hpp"

namespace driftless::fields {
namespace {

enum class Color { kRed, kBlue };

struct Inner {
  double rate_dps = 1.0;
};

struct Demo {
  double duration_s = 10.0;
  double ratio = 0.5;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  Eigen::Matrix3d m_pct = Eigen::Matrix3d::Zero();
  bool on = false;
  int count = 3;
  std::string name = "x";
  Color color = Color::kRed;
  Inner inner;
};

const Table<Inner>& inner_table() {
  static const Table<Inner> t = {number<Inner>("rate", "dps", &Inner::rate_dps)};
  return t;
}

const Table<Demo>& demo_table() {
  static const Table<Demo> t = {
      number<Demo>("duration", "s", &Demo::duration_s),
      number<Demo>("ratio", "", &Demo::ratio),
      vector<Demo>("axis", "", &Demo::axis),
      matrix3<Demo>("m", "pct", &Demo::m_pct),
      flag<Demo>("on", &Demo::on),
      integer<Demo>("count", &Demo::count, 0, 10),
      text<Demo>("name", &Demo::name),
      choice<Demo>("color", &Demo::color, Names<Color>{{"red", Color::kRed}, {"blue", Color::kBlue}}),
      block<Demo>("inner", &Demo::inner, &inner_table),
  };
  return t;
}

// a tiny document builder: `key: scalar` entries on consecutive lines, starting at line 1
Node doc(std::vector<std::pair<std::string, Node>> kv) {
  Node m = Node::map();
  m.line = 1;
  std::size_t line = 1;
  for (auto& [k, v] : kv) {
    v.line = line;
    m.entries.push_back(Entry{k, line++, v});
  }
  return m;
}

Node num(const std::string& t) { return Node::scalar(t); }
Node list(std::vector<std::string> xs) {
  std::vector<Node> items;
  for (auto& x : xs) items.push_back(Node::scalar(x));
  return Node::list(items);
}

std::string error_of(const Node& n) {
  Demo d;
  try {
    read_block(demo_table(), d, n, Context{"demo.yaml", "top"});
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Fields, OneTableParsesAndEmitsEveryRow) {
  Demo d;
  Node inner = Node::map();
  inner.add("rate_dps", num("2"));
  read_block(demo_table(), d,
             doc({{"duration_s", num("20")}, {"ratio", num("0.25")}, {"axis", list({"1", "0", "0"})},
                  {"m_pct", list({"0", "1", "2", "3", "0", "4", "5", "6", "0"})}, {"on", num("yes")},
                  {"count", num("7")}, {"name", num("hello")}, {"color", num("blue")}, {"inner", inner}}),
             Context{"demo.yaml", ""});
  EXPECT_EQ(d.duration_s, 20.0);
  EXPECT_EQ(d.ratio, 0.25);
  EXPECT_EQ(d.axis, Eigen::Vector3d::UnitX());
  EXPECT_EQ(d.m_pct(1, 2), 4.0);
  EXPECT_TRUE(d.on);
  EXPECT_EQ(d.count, 7);
  EXPECT_EQ(d.name, "hello");
  EXPECT_EQ(d.color, Color::kBlue);
  EXPECT_EQ(d.inner.rate_dps, 2.0);
  // emit: every key, canonical names, table order; reading it back gives the same struct
  const Node out = write_block(demo_table(), d);
  std::vector<std::string> keys;
  for (const auto& e : out.entries) keys.push_back(e.key);
  EXPECT_EQ(keys, (std::vector<std::string>{"duration_s", "ratio", "axis", "m_pct", "on", "count", "name", "color",
                                            "inner"}));
  EXPECT_EQ(out.find("duration_s")->text, "20");
  EXPECT_EQ(out.find("on")->text, "true");
  EXPECT_EQ(out.find("color")->text, "blue");
  Demo back;
  read_block(demo_table(), back, out, Context{});
  EXPECT_EQ(back.m_pct, d.m_pct);
  EXPECT_EQ(back.inner.rate_dps, 2.0);
  EXPECT_EQ(key_list(demo_table()), "duration_s, ratio, axis, m_pct, on, count, name, color, inner");
}

TEST(Fields, KeysInAnotherUnitOfTheSameQuantityConvert) {
  Demo d;
  Node inner = Node::map();
  inner.add("rate_dph", num("3600"));
  read_block(demo_table(), d, doc({{"duration_min", num("2")}, {"inner", inner}, {"m_ppm", list({"0", "1e4", "0", "0", "0", "0", "0", "0", "0"})}}),
             Context{});
  EXPECT_EQ(d.duration_s, 120.0);
  EXPECT_NEAR(d.inner.rate_dps, 1.0, 1e-15);
  EXPECT_NEAR(d.m_pct(0, 1), 1.0, 1e-15);
  // a value may carry the key's unit after the number
  read_block(demo_table(), d, doc({{"duration_s", num("600 s")}, {"ratio", num("+0.5")}}), Context{});
  EXPECT_EQ(d.duration_s, 600.0);
  read_block(demo_table(), d, doc({{"duration_h", num("0.5 h")}}), Context{});
  EXPECT_EQ(d.duration_s, 1800.0);
}

TEST(Fields, ErrorsNameFileLineKeyAndWhatWasExpected) {
  std::string e = error_of(doc({{"ratio", num("1")}, {"duraton_s", num("1")}}));
  EXPECT_EQ(e.rfind("demo.yaml:2: top.duraton_s: unknown key (allowed here: duration_s, ratio", 0), 0u) << e;
  e = error_of(doc({{"duration_deg", num("1")}}));
  EXPECT_NE(e.find("demo.yaml:1: top.duration_deg: inconsistent units: 'duration_deg' is in deg but this field is in s"),
            std::string::npos) << e;
  e = error_of(doc({{"duration", num("1")}}));
  EXPECT_NE(e.find("needs its unit in the key: write 'duration_s'"), std::string::npos) << e;
  e = error_of(doc({{"ratio_pct", num("1")}}));
  EXPECT_NE(e.find("this field has none; write 'ratio'"), std::string::npos) << e;
  e = error_of(doc({{"duration_s", num("10 deg")}}));
  EXPECT_NE(e.find("value '10 deg' carries unit 'deg' but this field is in s"), std::string::npos) << e;
  e = error_of(doc({{"ratio", num("abc")}}));
  EXPECT_NE(e.find("demo.yaml:1: top.ratio: expected a number, got 'abc'"), std::string::npos) << e;
  e = error_of(doc({{"ratio", num(".inf")}}));
  EXPECT_NE(e.find("expected a finite number"), std::string::npos) << e;
  e = error_of(doc({{"count", num("2.5")}}));
  EXPECT_NE(e.find("expected a whole number in [0, 10]"), std::string::npos) << e;
  e = error_of(doc({{"count", num("11")}}));
  EXPECT_NE(e.find("expected a whole number in [0, 10]"), std::string::npos) << e;
  e = error_of(doc({{"on", num("maybe")}}));
  EXPECT_NE(e.find("expected true or false, got 'maybe'"), std::string::npos) << e;
  e = error_of(doc({{"color", num("green")}}));
  EXPECT_NE(e.find("expected one of red, blue, got 'green'"), std::string::npos) << e;
  e = error_of(doc({{"axis", list({"1", "0"})}}));
  EXPECT_NE(e.find("expected a list of 3 numbers"), std::string::npos) << e;
  e = error_of(doc({{"m_pct", list({"1", "0"})}}));
  EXPECT_NE(e.find("3x3"), std::string::npos) << e;
  Node inner = Node::map();
  Node bad = num("x");
  bad.line = 9;
  inner.add("rate_dps", bad);
  e = error_of(doc({{"inner", inner}}));
  EXPECT_NE(e.find("demo.yaml:9: top.inner.rate_dps: expected a number in deg/s, got 'x'"), std::string::npos) << e;
  e = error_of(doc({{"inner", num("3")}}));
  EXPECT_NE(e.find("top.inner: expected a mapping"), std::string::npos) << e;
}

TEST(Fields, DuplicateKeysAreRefusedNamingBothLines) {
  Node inner = Node::map();
  inner.entries.push_back(Entry{"rate_dps", 4, num("1")});
  inner.entries.push_back(Entry{"rate_dps", 6, num("2")});
  const Node d = doc({{"ratio", num("1")}, {"inner", inner}});
  try {
    check_unique_keys(d, "demo.yaml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "demo.yaml");
    EXPECT_EQ(e.line(), 6u);
    EXPECT_EQ(e.key(), "inner.rate_dps");
    EXPECT_NE(std::string(e.what()).find("lines 4 and 6"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(check_unique_keys(doc({{"a", num("1")}, {"b", num("2")}}), "x"));
}

// the row kinds of the calibration files and the sweep: lists of blocks, null numbers, optional
// rows, rows written only when they apply, required keys
struct Item {
  std::string name;
  double t_s = 0.0;
};
struct Doc {
  std::vector<Item> items;
  double lat_deg = kNaN;
  bool has_extra = false;
  double extra = 0.0;
  bool custom = false;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  std::vector<std::string> tags;
};

const Table<Item>& item_table() {
  static const Table<Item> t = {text<Item>("name", &Item::name), number<Item>("t", "s", &Item::t_s)};
  return t;
}

const Table<Doc>& doc_table() {
  static const Table<Doc> t = {
      block_list<Doc>("items", &Doc::items, &item_table),
      number_or_null<Doc>("lat", "deg", &Doc::lat_deg),
      optional_row(number<Doc>("extra", "", &Doc::extra), &Doc::has_extra),
      written_if<Doc>(vector<Doc>("axis", "", &Doc::axis), [](const Doc& d) { return d.custom; }),
      text_list<Doc>("tags", &Doc::tags),
  };
  return t;
}

Node item(const std::string& name, const std::string& t_key, const std::string& t) {
  Node m = Node::map(true);
  m.add("name", Node::scalar(name));
  m.add(t_key, Node::scalar(t));
  return m;
}

TEST(Fields, ListsNullsOptionalAndRequiredRows) {
  // GIVEN a list of blocks (one key in another unit), a null number and a text list
  Node items = Node::list({item("a", "t_s", "1.5"), item("b", "t_ms", "250")}, false);
  Node tags = list({"x", "y"});
  const Node in = doc({{"items", items}, {"lat_deg", Node{}}, {"tags", tags}});
  Doc d;
  d.has_extra = false;
  const auto given = read_block(doc_table(), d, in, Context{"d.yaml", ""});
  // THEN each item went through its table, units converted; null reads as NaN
  ASSERT_EQ(d.items.size(), 2u);
  EXPECT_EQ(d.items[1].name, "b");
  EXPECT_DOUBLE_EQ(d.items[1].t_s, 0.25);
  EXPECT_TRUE(std::isnan(d.lat_deg));
  EXPECT_EQ(d.tags, (std::vector<std::string>{"x", "y"}));
  EXPECT_FALSE(d.has_extra);
  EXPECT_NO_THROW(require(doc_table(), given, in, Context{"d.yaml", ""}, {"items", "lat_deg"}));
  try {
    require(doc_table(), given, in, Context{"d.yaml", ""}, {"items", "extra"});
    FAIL() << "a missing required key passed";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "extra");
    EXPECT_NE(std::string(e.what()).find("missing"), std::string::npos) << e.what();
  }
  // AND an item error names its index
  Node bad_items = Node::list({item("a", "t_s", "1"), item("b", "t_deg", "2")}, false);
  try {
    Doc e;
    read_block(doc_table(), e, doc({{"items", bad_items}}), Context{"d.yaml", ""});
    FAIL() << "a time in degrees passed";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "items[1].t_deg");
  }
  // WHEN written: the optional row and the conditional row stay out until they apply; NaN is null
  Node out = write_block(doc_table(), d);
  EXPECT_EQ(out.find("extra"), nullptr);
  EXPECT_EQ(out.find("axis"), nullptr);
  EXPECT_TRUE(out.find("lat_deg")->is_null());
  EXPECT_TRUE(out.find("items")->items[0].flow);
  EXPECT_EQ(out.find("items")->items[1].find("t_s")->text, "0.25");
  d.has_extra = true;
  d.custom = true;
  d.lat_deg = 52.0;
  out = write_block(doc_table(), d);
  EXPECT_EQ(out.find("extra")->text, "0");
  EXPECT_NE(out.find("axis"), nullptr);
  EXPECT_EQ(out.find("lat_deg")->text, "52");
  // AND reading an optional row sets its flag
  Doc f;
  read_block(doc_table(), f, doc({{"extra", num("3")}}), Context{"d.yaml", ""});
  EXPECT_TRUE(f.has_extra);
  EXPECT_EQ(f.extra, 3.0);
}

TEST(Fields, FlatFormReadsLinesAndRefusesDuplicates) {
  std::istringstream in("# comment\n---\nratio: 0.75  # why\nname: \"quoted text\"\n\ncount: 4\n");
  const Node n = read_flat(in, "c.cfg");
  ASSERT_EQ(n.entries.size(), 3u);
  EXPECT_EQ(n.entries[0].line, 3u);
  EXPECT_EQ(n.find("name")->text, "quoted text");
  std::ostringstream out;
  write_flat(out, n);
  EXPECT_EQ(out.str(), "ratio: 0.75\nname: quoted text\ncount: 4\n");
  std::istringstream dup("ratio: 1\ncount: 2\nratio: 3\n");
  try {
    read_flat(dup, "c.cfg");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "c.cfg:3: ratio: key given twice (lines 1 and 3); keep one");
  }
  std::istringstream junk("ratio 1\n");
  EXPECT_THROW(read_flat(junk, "c.cfg"), InputError);
}

TEST(Units, OneTableEverySuffixOnceAndFactorsAgainstClosedForms) {
  const auto& t = units::table();
  for (std::size_t i = 0; i < t.size(); ++i) {
    for (std::size_t j = i + 1; j < t.size(); ++j) EXPECT_NE(t[i].suffix, t[j].suffix);
    EXPECT_FALSE(t[i].spellings.empty()) << t[i].suffix;
  }
  const auto f = [](const char* a, const char* b) { return units::factor(*units::find(a), *units::find(b)); };
  EXPECT_EQ(f("dps", "dps"), 1.0);
  EXPECT_NEAR(f("dph", "dps"), 1.0 / 3600.0, 1e-18);
  EXPECT_NEAR(f("deg_rth", "dps_rthz"), 1.0 / 60.0, 1e-17);       // 1 deg/sqrt(h) = 1/60 deg/s/sqrt(Hz)
  EXPECT_NEAR(f("dph_rth", "dps_rts"), 1.0 / 216000.0, 1e-20);    // (1/3600) / sqrt(3600)
  EXPECT_NEAR(f("mg", "mps2"), 9.80665e-3, 1e-17);
  EXPECT_NEAR(f("g", "mg"), 1000.0, 1e-12);
  EXPECT_NEAR(f("kmh", "mps"), 1.0 / 3.6, 1e-16);
  EXPECT_NEAR(f("arcsec", "deg"), 1.0 / 3600.0, 1e-18);
  EXPECT_NEAR(f("h", "s"), 3600.0, 0.0);
  EXPECT_EQ(units::find("dps")->quantity, units::Quantity::kRate);
  EXPECT_EQ(units::find("nonsense"), nullptr);
  EXPECT_EQ(units::list_of(units::Quantity::kFrequency), "hz (Hz), khz (kHz)");
}

}  // namespace
}  // namespace driftless::fields
