// Sweep file, grid expansion, parallel runner and result table. Format: docs/sweep.md.
#include "studies/sweep.hpp"

#include "estimator/random.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "estimator/fields.hpp"
#include "estimator/input_error.hpp"
#include "estimator/numbers.hpp"
#include "estimator/output_file.hpp"
#include "report/gnuplot.hpp"
#include "twin/yaml_doc.hpp"

namespace driftless::studies {
namespace {

// a CSV number: exact, NaN as an empty field
std::string fmt_double(double v) { return std::isnan(v) ? std::string() : exact_number(v); }

// CSV field: no commas or quotes or newlines in our text fields
std::string csv_text(std::string s) {
  for (char& c : s) {
    if (c == ',' || c == '"' || c == '\n' || c == '\r') c = ';';
  }
  return s;
}

}  // namespace

void SweepConfig::validate() const {
  const std::string f = file.empty() ? std::string("sweep") : file.string();
  if (runner != "fast" && runner != "twin" && runner != "fdi" && runner != "fdi_twin") {
    throw std::invalid_argument(f + ": runner must be fast, twin, fdi or fdi_twin (got '" + runner + "')");
  }
  if (monte_carlo < 1) throw std::invalid_argument(f + ": monte_carlo must be >= 1");
  if (duration_s < 0) throw std::invalid_argument(f + ": duration_s must be >= 0 s");
  std::set<std::string> names;
  for (const auto& a : grid) {
    if (a.name.empty()) throw std::invalid_argument(f + ": a grid axis has no name");
    if (!names.insert(a.name).second) {
      throw std::invalid_argument(f + ": grid axis '" + a.name + "' appears twice");
    }
    if (a.values.empty()) throw std::invalid_argument(f + ": grid axis '" + a.name + "' has no values");
    if (a.set.empty()) throw std::invalid_argument(f + ": grid axis '" + a.name + "' sets no key");
  }
  for (const auto& p : plots) {
    if (!names.count(p.x)) {
      throw std::invalid_argument(f + ": plot x '" + p.x + "' is not a grid axis");
    }
    if (!p.series.empty() && !names.count(p.series)) {
      throw std::invalid_argument(f + ": plot series '" + p.series + "' is not a grid axis");
    }
    if (p.y.empty()) throw std::invalid_argument(f + ": a plot needs at least one y metric");
  }
}

std::size_t SweepConfig::points() const {
  std::size_t n = 1;
  for (const auto& a : grid) n *= a.values.size();
  return n;
}

namespace {

using fields::Node;
using fields::Reading;
using fields::Table;

// a value that may be one text or a list of texts (`set: a.b` or `set: [a.b, c.d]`)
fields::Row<std::vector<std::string>> one_or_more(const char* stem) {
  using V = std::vector<std::string>;
  return fields::custom<V>(
      stem, "",
      [](V& v, const Node& n, const Reading& r) {
        v.clear();
        if (!n.is_list()) return v.push_back(fields::read_text(n, r));
        for (const auto& x : n.items) v.push_back(fields::read_text(x, r));
      },
      [](const V& v) -> std::optional<Node> {
        std::vector<Node> xs;
        for (const auto& x : v) xs.push_back(Node::scalar(x));
        return Node::list(std::move(xs));
      });
}

template <class T, class Acc>
fields::Row<T> texts(const char* stem, Acc acc) {
  const auto row = one_or_more(stem);
  return fields::custom<T>(
      stem, "", [row, acc](T& o, const Node& n, const Reading& r) { row.read(std::invoke(acc, o), n, r); },
      [row, acc](const T& o) { return row.write(std::invoke(acc, o)); });
}

// a grid axis given as a map; `range: [from, to, step]` comes before `values` whatever the order
struct AxisDoc {
  GridAxis axis;
  std::vector<double> range_values;
};

fields::Row<AxisDoc> range_row() {
  return fields::custom<AxisDoc>(
      "range", "",
      [](AxisDoc& a, const Node& n, const Reading& r) {
        if (!n.is_list() || n.items.size() != 3) r.fail(n, "'range' is [from, to, step]");
        const double from = fields::read_number(n.items[0], r), to = fields::read_number(n.items[1], r),
                     step = fields::read_number(n.items[2], r);
        if (!(step > 0) || to < from) r.fail(n, "'range' needs step > 0 and to >= from");
        a.range_values.clear();
        for (double v = from; v <= to + 1e-9 * step; v += step) a.range_values.push_back(v);
      },
      [](const AxisDoc&) -> std::optional<Node> { return std::nullopt; });  // written as its values
}

// an axis's values: a list of numbers (also the whole axis in the short form `name: [1, 2]`)
void read_values(AxisDoc& a, const Node& n, const Reading& r) {
  if (!n.is_list()) r.fail(n, "grid axis '" + a.axis.name + "': values must be a list");
  a.axis.values.clear();
  for (const auto& x : n.items) a.axis.values.push_back(fields::read_number(x, r));
}

fields::Row<AxisDoc> values_row() {
  return fields::custom<AxisDoc>(
      "values", "", read_values,
      [](const AxisDoc& a) -> std::optional<Node> {
        std::vector<Node> xs;
        for (double v : a.axis.values) xs.push_back(Node::scalar(exact_number(v)));
        return Node::list(std::move(xs));
      });
}

const Table<AxisDoc>& axis_table() {
  using A = AxisDoc;
  static const Table<A> t = {
      texts<A>("set", [](auto& a) -> auto& { return a.axis.set; }),
      values_row(),
      range_row(),
      fields::flag<A>("vector3", [](auto& a) -> auto& { return a.axis.vector3; }),
      fields::flag<A>("boolean", [](auto& a) -> auto& { return a.axis.boolean; }),
  };
  return t;
}

// grid: {name: [values] | {set, values | range, vector3, boolean}, ...}, axes in file order
fields::Row<SweepConfig> grid_row() {
  return fields::custom<SweepConfig>(
      "grid", "",
      [](SweepConfig& c, const Node& n, const Reading& r) {
        if (!n.is_map()) r.fail(n, "'grid' must map axis names to value lists or {set, values}");
        for (const auto& e : n.entries) {
          AxisDoc a;
          a.axis.name = e.key;
          const fields::Context ctx = r.ctx.child(e.key);
          if (e.value.is_map()) {
            fields::read_block(axis_table(), a, e.value, ctx);
          } else {
            read_values(a, e.value, Reading{ctx});
          }
          a.axis.values.insert(a.axis.values.begin(), a.range_values.begin(), a.range_values.end());
          if (a.axis.set.empty()) a.axis.set.push_back(a.axis.name);
          c.grid.push_back(std::move(a.axis));
        }
      },
      [](const SweepConfig& c) -> std::optional<Node> {
        Node m = Node::map();
        for (const auto& ax : c.grid) m.add(ax.name, fields::write_block(axis_table(), AxisDoc{ax, {}}, true));
        return m;
      });
}

// fixed: {key.path: value}: each value kept as YAML text (one line), applied to every run
fields::Row<SweepConfig> fixed_row() {
  return fields::custom<SweepConfig>(
      "fixed", "",
      [](SweepConfig& c, const Node& n, const Reading& r) {
        if (!n.is_map()) r.fail(n, "'fixed' must map key paths to values");
        for (const auto& e : n.entries) {
          Node v = e.value;
          v.flow = true;
          v.quoted = false;
          c.fixed.emplace_back(e.key, twin::to_yaml(v));
        }
      },
      [](const SweepConfig& c) -> std::optional<Node> {
        if (c.fixed.empty()) return std::nullopt;
        Node m = Node::map();
        for (const auto& [k, v] : c.fixed) m.add(k, twin::parse_yaml(v, "fixed." + k));
        return m;
      });
}

const Table<PlotSpec>& plot_table() {
  using P = PlotSpec;
  static const Table<P> t = {
      fields::text<P>("x", &P::x),
      texts<P>("y", &P::y),
      fields::text<P>("series", &P::series, false, true),
      fields::flag<P>("logx", &P::logx),
      fields::flag<P>("logy", &P::logy),
  };
  return t;
}

// plots: one plot map or a list of them (`plot:` is the same key)
fields::Row<SweepConfig> plots_row(const char* stem) {
  return fields::custom<SweepConfig>(
      stem, "",
      [](SweepConfig& c, const Node& n, const Reading& r) {
        const std::vector<Node> one{n};
        const std::vector<Node>& items = n.is_map() ? one : n.items;
        if (!n.is_map() && !n.is_list()) r.fail(n, "expected a plot {x, y, ...} or a list of them");
        for (std::size_t i = 0; i < items.size(); ++i) {
          const fields::Context ctx{r.ctx.file, r.ctx.path + (n.is_map() ? "" : "[" + std::to_string(i) + "]")};
          PlotSpec p;
          const auto given = fields::read_block(plot_table(), p, items[i], ctx);
          fields::require(plot_table(), given, items[i], ctx, {"x"});
          c.plots.push_back(std::move(p));
        }
      },
      [](const SweepConfig& c) -> std::optional<Node> {
        std::vector<Node> xs;
        for (const auto& p : c.plots) xs.push_back(fields::write_block(plot_table(), p, true));
        return Node::list(std::move(xs), false);
      });
}

const Table<SweepConfig>& sweep_table() {
  using C = SweepConfig;
  static const Table<C> t = {
      fields::text<C>("name", &C::name),
      fields::text<C>("description", &C::description, false, true),
      fields::text<C>("runner", &C::runner),
      fields::custom<C>(
          "scenario", "", [](C& c, const Node& n, const Reading& r) { c.scenario = fields::read_text(n, r); },
          [](const C& c) -> std::optional<Node> {
            if (c.scenario.empty()) return std::nullopt;
            return Node::scalar(c.scenario.string());
          }),
      fields::number<C>("duration", "s", &C::duration_s),
      fields::integer<C>("monte_carlo", &C::monte_carlo, 1, 1000000),
      fields::integer<C>("seed", &C::seed, 0, INT64_MAX),
      grid_row(),
      fixed_row(),
      fields::written_if<C>(plots_row("plot"), [](const C&) { return false; }),  // read as plots
      plots_row("plots"),
  };
  return t;
}

}  // namespace

SweepConfig parse_sweep(const std::string& yaml_text, const std::string& file,
                        const std::filesystem::path& base_dir) {
  const Node root = twin::parse_yaml(yaml_text, file);
  if (!root.is_map()) throw InputError(file, root.line, "", "a sweep file is a YAML map (docs/sweep.md)");
  SweepConfig c;
  c.file = file;
  c.name = std::filesystem::path(file).stem().string();
  fields::read_block(sweep_table(), c, root, fields::Context{file, ""});
  // a bare word without a suffix is a built-in scenario name; a file is relative to the sweep's
  if (c.scenario.has_extension() && c.scenario.is_relative()) c.scenario = base_dir / c.scenario;
  with_location("", 0, "", [&] { c.validate(); });  // validate() names the file itself
  return c;
}

std::string sweep_yaml(const SweepConfig& c) { return twin::to_yaml(fields::write_block(sweep_table(), c)) + "\n"; }

SweepConfig load_sweep(const std::filesystem::path& path) {
  return parse_sweep(twin::read_yaml_text(path), path.string(), path.parent_path());
}

std::uint64_t run_seed(std::uint64_t base_seed, int mc) {
  // 31 bits: scenario files and other tools read a seed as a plain integer
  return rnd::mix64(base_seed * 0x100000001B3ull + static_cast<std::uint64_t>(mc)) >> 33;
}

std::vector<RunSpec> expand(const SweepConfig& cfg) {
  std::vector<RunSpec> out;
  const std::size_t points = cfg.points();
  out.reserve(points * static_cast<std::size_t>(cfg.monte_carlo));
  for (std::size_t p = 0; p < points; ++p) {
    std::vector<double> values(cfg.grid.size());
    std::size_t rest = p;
    for (std::size_t a = cfg.grid.size(); a-- > 0;) {
      const auto& ax = cfg.grid[a];
      values[a] = ax.values[rest % ax.values.size()];
      rest /= ax.values.size();
    }
    for (int mc = 0; mc < cfg.monte_carlo; ++mc) {
      RunSpec s;
      s.index = out.size();
      s.point = p;
      s.mc = mc;
      s.seed = run_seed(cfg.seed, mc);
      s.values = values;
      out.push_back(std::move(s));
    }
  }
  return out;
}

std::vector<RunResult> run_parallel(const std::vector<RunSpec>& specs,
                                    const std::vector<std::size_t>& indices, const SweepJob& job,
                                    int threads,
                                    const std::function<void(std::size_t, std::size_t)>& on_done,
                                    const std::atomic<bool>* stop) {
  std::vector<RunResult> results(indices.size());
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = std::min<int>(threads, std::max<std::size_t>(1, indices.size()));
  std::atomic<std::size_t> next{0};
  std::mutex mu;
  std::size_t done = 0;
  auto worker = [&] {
    for (;;) {
      const std::size_t k = next.fetch_add(1);
      if (k >= indices.size()) return;
      const RunSpec& spec = specs.at(indices[k]);
      RunResult r;
      r.index = spec.index;
      const auto t0 = std::chrono::steady_clock::now();
      if (stop && stop->load()) {
        r.error = "stopped";
      } else {
        try {
          r.metrics = job(spec);
          r.ok = true;
        } catch (const std::exception& e) {
          r.error = csv_text(e.what());
        }
      }
      r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      results[k] = std::move(r);
      std::lock_guard<std::mutex> lock(mu);
      ++done;
      if (on_done) on_done(done, indices.size());
    }
  };
  std::vector<std::thread> pool;
  for (int i = 1; i < threads; ++i) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  return results;
}

std::string serialize_result(const RunResult& r) {
  std::ostringstream out;
  out << r.index << '\t' << (r.ok ? 1 : 0) << '\t' << r.wall_s << '\t' << csv_text(r.error);
  for (const auto& [k, v] : r.metrics) out << '\t' << k << '=' << exact_number(v);
  return out.str();
}

RunResult parse_result(const std::string& line) {
  std::vector<std::string> f;
  std::size_t a = 0;
  for (;;) {
    const std::size_t b = line.find('\t', a);
    f.push_back(line.substr(a, b == std::string::npos ? std::string::npos : b - a));
    if (b == std::string::npos) break;
    a = b + 1;
  }
  if (f.size() < 4) throw std::runtime_error("sweep: malformed gathered result line: " + line);
  RunResult r;
  r.index = std::stoull(f[0]);
  r.ok = f[1] == "1";
  r.wall_s = std::strtod(f[2].c_str(), nullptr);
  r.error = f[3];
  for (std::size_t i = 4; i < f.size(); ++i) {
    const auto eq = f[i].find('=');
    if (eq == std::string::npos) throw std::runtime_error("sweep: malformed metric: " + f[i]);
    r.metrics.emplace_back(f[i].substr(0, eq), std::strtod(f[i].c_str() + eq + 1, nullptr));
  }
  return r;
}

std::vector<std::map<std::string, Aggregate>> summarize(const SweepConfig& cfg,
                                                        const std::vector<RunResult>& results) {
  const std::size_t points = cfg.points();
  std::vector<std::map<std::string, std::vector<double>>> vals(points);
  for (const auto& r : results) {
    if (!r.ok) continue;
    const std::size_t p = r.index / static_cast<std::size_t>(cfg.monte_carlo);
    if (p >= points) continue;
    for (const auto& [k, v] : r.metrics) vals[p][k].push_back(v);
  }
  std::vector<std::map<std::string, Aggregate>> out(points);
  for (std::size_t p = 0; p < points; ++p) {
    for (const auto& [k, v] : vals[p]) {
      Aggregate g;
      g.n = v.size();
      double s = 0, s2 = 0;
      g.min = g.max = v.front();
      for (double x : v) {
        s += x;
        s2 += x * x;
        g.min = std::min(g.min, x);
        g.max = std::max(g.max, x);
      }
      g.mean = s / g.n;
      g.rms = std::sqrt(s2 / g.n);
      double ss = 0;
      for (double x : v) ss += (x - g.mean) * (x - g.mean);
      g.std = g.n > 1 ? std::sqrt(ss / (g.n - 1)) : 0.0;
      out[p][k] = g;
    }
  }
  return out;
}

std::size_t write_outputs(const SweepConfig& cfg, const std::vector<RunSpec>& specs,
                          const std::vector<RunResult>& results_in, const std::filesystem::path& dir,
                          bool run_gnuplot, std::vector<std::string>* plot_warnings) {
  std::filesystem::create_directories(dir);
  std::vector<const RunResult*> by_index(specs.size(), nullptr);
  for (const auto& r : results_in) {
    if (r.index >= specs.size() || by_index[r.index]) {
      throw std::runtime_error("sweep: result index " + std::to_string(r.index) +
                               " out of range or duplicated");
    }
    by_index[r.index] = &r;
  }
  // metric columns: union in first-seen order (successful runs)
  std::vector<std::string> metrics;
  for (const auto* r : by_index) {
    if (!r) continue;
    for (const auto& [k, v] : r->metrics) {
      if (std::find(metrics.begin(), metrics.end(), k) == metrics.end()) metrics.push_back(k);
    }
  }
  std::size_t failed = 0;
  {
    std::ostringstream out;
    out << "# sweep: " << csv_text(cfg.name) << "\n# runner: " << cfg.runner
        << "\n# monte_carlo: " << cfg.monte_carlo << "\n# seed: " << cfg.seed << "\n";
    out << "run,point,mc,seed";
    for (const auto& a : cfg.grid) out << ',' << a.name;
    out << ",status";
    for (const auto& m : metrics) out << ',' << m;
    out << '\n';
    for (std::size_t i = 0; i < specs.size(); ++i) {
      const RunSpec& s = specs[i];
      out << s.index << ',' << s.point << ',' << s.mc << ',' << s.seed;
      for (double v : s.values) out << ',' << fmt_double(v);
      const RunResult* r = by_index[i];
      if (!r || !r->ok) {
        ++failed;
        out << ",failed: " << (r ? csv_text(r->error) : std::string("missing (never ran)"));
        for (std::size_t m = 0; m < metrics.size(); ++m) out << ',';
        out << '\n';
        continue;
      }
      out << ",ok";
      for (const auto& m : metrics) {
        auto it = std::find_if(r->metrics.begin(), r->metrics.end(),
                               [&](const auto& kv) { return kv.first == m; });
        out << ',' << (it == r->metrics.end() ? std::string() : fmt_double(it->second));
      }
      out << '\n';
    }
    io::write_file(dir / "runs.csv", out.str());
  }
  std::vector<RunResult> ok_results;
  for (const auto* r : by_index) {
    if (r) ok_results.push_back(*r);
  }
  const auto agg = summarize(cfg, ok_results);
  {
    std::ostringstream out;
    out << "point";
    for (const auto& a : cfg.grid) out << ',' << a.name;
    out << ",n_ok";
    for (const auto& m : metrics) {
      out << ',' << m << "_mean," << m << "_std," << m << "_min," << m << "_max," << m << "_rms";
    }
    out << '\n';
    for (std::size_t p = 0; p < agg.size(); ++p) {
      out << p;
      for (std::size_t a = 0; a < cfg.grid.size(); ++a) {
        out << ',' << fmt_double(specs[p * cfg.monte_carlo].values[a]);
      }
      std::size_t n = 0;
      for (const auto& [k, g] : agg[p]) n = std::max(n, g.n);
      out << ',' << n;
      for (const auto& m : metrics) {
        auto it = agg[p].find(m);
        if (it == agg[p].end()) {
          out << ",,,,,";
          continue;
        }
        const Aggregate& g = it->second;
        out << ',' << fmt_double(g.mean) << ',' << fmt_double(g.std) << ',' << fmt_double(g.min)
            << ',' << fmt_double(g.max) << ',' << fmt_double(g.rms);
      }
      out << '\n';
    }
    io::write_file(dir / "summary.csv", out.str());
  }
  // gnuplot: one script (and PNG) per plotted metric, mean with +-std error bars
  for (const auto& p : cfg.plots) {
    const auto col = [&](const std::string& name) -> int {
      for (std::size_t a = 0; a < cfg.grid.size(); ++a) {
        if (cfg.grid[a].name == name) return static_cast<int>(a) + 2;
      }
      return -1;
    };
    for (const auto& y : p.y) {
      const auto mi = std::find(metrics.begin(), metrics.end(), y);
      if (mi == metrics.end()) continue;  // metric absent (e.g. every run failed)
      const int ycol = static_cast<int>(cfg.grid.size()) + 3 + 5 * static_cast<int>(mi - metrics.begin());
      const std::string stem = "plot_" + y + "_vs_" + p.x;
      std::ostringstream gp;
      gp << "set datafile separator ','\nset key top left\nset grid\n"
         << "set xlabel '" << p.x << "'\nset ylabel '" << y << " (mean +- std over "
         << cfg.monte_carlo << " seeds)'\nset title '" << csv_text(cfg.name) << "'\n";
      if (p.logx) gp << "set logscale x\n";
      if (p.logy) gp << "set logscale y\n";
      const int xcol = col(p.x);
      if (p.series.empty()) {
        gp << "plot 'summary.csv' every ::1 using " << xcol << ":" << ycol << ":" << ycol + 1
           << " with yerrorlines title '" << y << "'\n";
      } else {
        const int scol = col(p.series);
        const auto& ax = cfg.grid[scol - 2];
        gp << "plot ";
        for (std::size_t k = 0; k < ax.values.size(); ++k) {
          gp << (k ? ", \\\n     " : "") << "'summary.csv' every ::1 using ($" << scol
             << "==" << fmt_double(ax.values[k]) << "?$" << xcol << ":1/0):" << ycol << ":"
             << ycol + 1 << " with yerrorlines title '" << p.series << " = "
             << fmt_double(ax.values[k]) << "'";
        }
        gp << "\n";
      }
      report::Figure fig(stem, gp.str());
      fig.title_comment = "driftless sweep '" + csv_text(cfg.name) + "': " + y + " against " + p.x;
      fig.width_px = 800;
      fig.height_px = 560;
      fig.svg = false;
      fig.csv_defaults = false;
      if (!run_gnuplot) {
        io::write_file(dir / (stem + ".gp"), report::gnuplot_script(fig));
      } else if (const auto st = report::render(dir, fig); !st.ok && plot_warnings != nullptr) {
        plot_warnings->push_back(st.message);
      }
    }
  }
  return failed;
}

}  // namespace driftless::studies
