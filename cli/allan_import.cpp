// `driftless allan` on recordings the importers read: into memory, or streamed into octave
// accumulators with the channels shared between two threads.
#include <algorithm>
#include <exception>
#include <functional>
#include <optional>
#include <thread>

#include <fmt/core.h>

#include "cli/allan_input.hpp"
#include "estimator/allan_stream.hpp"

namespace driftless::cli::allan {
namespace {

constexpr std::size_t kBlockRows = 1u << 20;

std::string loc_word(const importers::ImuReader& r) {
  return r.info().format == importers::Format::kBag ? "message" : r.info().format == importers::Format::kNpy ? "row" : "line";
}

// rows of a block that start a new gap-free piece (a gap in the stamps before them)
std::vector<std::size_t> gap_rows(const importers::ImuBlock& b, importers::StampMonitor& mon, bool have_time, bool ignore) {
  std::vector<std::size_t> out;
  if (!have_time) return out;
  for (std::size_t r = 0; r < b.rows(); ++r) {
    if (mon.push(b.t_s[r], b.loc[r]) == importers::StampMonitor::Step::kGap && !ignore) out.push_back(r);
  }
  return out;
}

Loaded start_meta(const importers::ImuReader& r) {
  Loaded out;
  out.format = importers::to_string(r.info().format);
  out.notes = r.info().assumptions;
  for (const auto& ch : r.info().channels) {
    if (ch.quantity == importers::Quantity::kTemperature) {
      out.notes.push_back("column '" + ch.name + "' (temperature) is not analysed");
      continue;
    }
    out.channels.push_back({ch.name, ch.quantity, ch.axis, {}, {0}});
  }
  return out;
}

// channel index in the reader -> index in Loaded::channels (-1: not analysed)
std::vector<int> channel_map(const importers::ImuReader& r) {
  std::vector<int> map;
  int k = 0;
  for (const auto& ch : r.info().channels) map.push_back(ch.quantity == importers::Quantity::kTemperature ? -1 : k++);
  return map;
}

void finish_meta(Loaded& m, const InputArgs& a, const importers::ImuReader& r, importers::StampMonitor& mon,
                 std::size_t nan_rows) {
  m.stamps = mon.report();
  if (nan_rows > 0) {
    m.notes.push_back(fmt::format("{} missing values (empty or nan) left out{}", nan_rows,
                                  a.gaps_ignore ? "" : ", each a segment break"));
  }
  add_stamp_notes(m.stamps, loc_word(r), a.gaps_ignore, m.notes);
  m.rate_hz = resolve_rate(a.rate_hz, r.info().nominal_rate_hz, m.stamps, m.notes, a.source());
}

}  // namespace

namespace {

// appends a block's values of one channel, a segment break at each gap row and after each missing value
void append_channel(Channel& ch, const std::vector<double>& v, const std::vector<std::size_t>& gaps, bool& brk,
                    bool ignore, std::size_t& nan_rows) {
  std::size_t g = 0;
  for (std::size_t r = 0; r < v.size(); ++r) {
    while (g < gaps.size() && gaps[g] < r) ++g;
    brk = brk || (g < gaps.size() && gaps[g] == r);
    if (!std::isfinite(v[r])) {
      ++nan_rows;
      brk = brk || !ignore;
      continue;
    }
    if (brk && !ch.x.empty() && ch.segment_starts.back() != ch.x.size()) ch.segment_starts.push_back(ch.x.size());
    brk = false;
    ch.x.push_back(v[r]);
  }
}

bool all_finite(const std::vector<double>& v) {
  bool ok = true;
  for (const double x : v) ok &= std::isfinite(x);
  return ok;
}

}  // namespace

// A text record is asked for as one block: a gap-free channel with no missing value is then taken
// over as it is (no copy of its 40 MB at 5 M samples). Binary readers stage each block's raw rows
// (.npy: the file's bytes; bags: the messages), so they keep blocks of 2^20 rows.
Loaded load_imported(const InputArgs& a) {
  auto reader = importers::open_imu(a.source(), a.import_options());
  Loaded out = start_meta(*reader);
  const auto map = channel_map(*reader);
  importers::StampMonitor mon;
  importers::ImuBlock b;
  b.bare_untimed = true;  // stamps only for the gap check
  bool first = true;
  std::size_t nan_rows = 0;
  std::vector<bool> pending(out.channels.size(), false);
  const std::size_t estimate = reader->info().rows_estimate + reader->info().rows_estimate / 16;
  const auto format = reader->info().format;
  const bool whole = format == importers::Format::kText || format == importers::Format::kEuroc;
  while (reader->read(b, whole ? std::max(kBlockRows, estimate) : kBlockRows)) {
    if (first && reader->info().has_time) mon.learn(b.t_s);
    const auto gaps = gap_rows(b, mon, reader->info().has_time, a.gaps_ignore);
    for (std::size_t c = 0; c < map.size(); ++c) {
      if (map[c] < 0) continue;
      Channel& ch = out.channels[static_cast<std::size_t>(map[c])];
      if (first && whole && gaps.empty() && all_finite(b.values[c])) {
        ch.x = std::move(b.values[c]);
        continue;
      }
      // room at once (growing by doubling copies and faults in the pages again), geometric beyond the estimate
      const std::size_t need = ch.x.size() + b.rows();
      if (ch.x.capacity() < need) ch.x.reserve(std::max({estimate, need, ch.x.size() + ch.x.size() / 2}));
      bool brk = pending[static_cast<std::size_t>(map[c])];
      append_channel(ch, b.values[c], gaps, brk, a.gaps_ignore, nan_rows);
      pending[static_cast<std::size_t>(map[c])] = brk;
    }
    first = false;
  }
  finish_meta(out, a, *reader, mon, nan_rows);
  return out;
}

namespace {

// a block read ahead, with the rows that start a new gap-free piece
struct Staged {
  importers::ImuBlock block;
  std::vector<std::size_t> gaps;
  bool full = false;
};

// runs `side` on a new thread and `here` on this one; rethrows the first failure after both ended
template <class F, class G>
void both(F&& side, G&& here) {
  std::exception_ptr side_error, here_error;
  std::thread t([&] {
    try {
      side();
    } catch (...) {
      side_error = std::current_exception();
    }
  });
  try {
    here();
  } catch (...) {
    here_error = std::current_exception();
  }
  t.join();
  if (side_error) std::rethrow_exception(side_error);
  if (here_error) std::rethrow_exception(here_error);
}

// one channel's accumulators (one per deviation), fed the finite runs between breaks
struct ChannelSink {
  std::vector<est::StreamingOctaveDeviation> acc;
  std::optional<BlockMeans> seconds;  // the motion check's 1 s means (watched channels)
  bool pending_break = false;
  std::size_t nan = 0;
  void feed(const std::vector<double>& v, const std::vector<std::size_t>& gaps, bool ignore) {
    if (seconds) seconds->push(v);
    std::size_t begin = 0, g = 0;
    auto flush = [&](std::size_t end) {
      if (end > begin) {
        for (auto& x : acc) x.push(std::span<const double>(v.data() + begin, end - begin));
      }
    };
    for (std::size_t r = 0; r < v.size(); ++r) {
      const bool gap = g < gaps.size() && gaps[g] == r;
      if (gap) ++g;
      if (gap || pending_break) {
        flush(r);
        begin = r;
        for (auto& x : acc) x.break_segment();
        pending_break = false;
      }
      if (!std::isfinite(v[r])) {
        flush(r);
        begin = r + 1;
        ++nan;
        pending_break = !ignore;
      }
    }
    flush(v.size());
  }
};

// the rate the first block shows, for the 1 s blocks of the motion check while the stream is read:
// --rate, the file's own, else its stamps' mean rate (right for regular, jittering and bursty stamps)
double first_block_rate(const InputArgs& a, const importers::ImuReader& r, const importers::ImuBlock& b) {
  if (a.rate_hz > 0.0) return a.rate_hz;
  if (r.info().nominal_rate_hz > 0.0) return r.info().nominal_rate_hz;
  if (b.t_s.size() < 2 || !(b.t_s.back() > b.t_s.front())) return 0.0;
  return static_cast<double>(b.t_s.size() - 1) / (b.t_s.back() - b.t_s.front());
}

void watch_for_motion(std::vector<ChannelSink>& sinks, const Loaded& meta, double rate_hz) {
  if (!(rate_hz > 0.0)) return;
  for (std::size_t c = 0; c < sinks.size(); ++c) {
    if (watched_for_motion(meta.channels[c].name, meta.channels[c].quantity)) sinks[c].seconds.emplace(rate_hz);
  }
}

}  // namespace

Streamed stream_octaves(const InputArgs& a, const std::vector<est::Deviation>& devs, double confidence,
                        std::size_t exact_up_to_m) {
  auto reader = importers::open_imu(a.source(), a.import_options());
  Streamed out;
  out.meta = start_meta(*reader);
  const auto map = channel_map(*reader);
  std::vector<ChannelSink> sinks(out.meta.channels.size());
  for (auto& s : sinks) {
    for (const auto d : devs) {
      est::StreamingOptions so;
      so.deviation = d;
      so.confidence = confidence;
      so.exact_up_to_m = exact_up_to_m;
      s.acc.emplace_back(so);
    }
  }
  importers::StampMonitor mon;
  // the next block is read (and its stamps checked) on its own thread while this one and a helper
  // feed the accumulators with the current block: reading and summing overlap
  Staged cur, next;
  cur.block.bare_untimed = next.block.bare_untimed = true;
  bool first = true;
  auto read_into = [&](Staged& st) {
    st.full = reader->read(st.block, kBlockRows);
    if (st.full && first && reader->info().has_time) mon.learn(st.block.t_s);
    first = false;
    st.gaps = st.full ? gap_rows(st.block, mon, reader->info().has_time, a.gaps_ignore) : std::vector<std::size_t>{};
  };
  read_into(cur);
  const double watch_rate_hz = first_block_rate(a, *reader, cur.block);
  watch_for_motion(sinks, out.meta, watch_rate_hz);
  while (cur.full) {
    // the channels split between this thread and one more
    auto work = [&](std::size_t from, std::size_t step) {
      for (std::size_t c = from; c < map.size(); c += step) {
        if (map[c] >= 0) sinks[static_cast<std::size_t>(map[c])].feed(cur.block.values[c], cur.gaps, a.gaps_ignore);
      }
    };
    both([&] { read_into(next); }, [&] { both([&] { work(1, 2); }, [&] { work(0, 2); }); });
    std::swap(cur, next);
  }
  std::size_t nan = 0;
  for (const auto& s : sinks) nan += s.nan;
  finish_meta(out.meta, a, *reader, mon, nan);
  for (auto& s : sinks) {
    std::vector<est::AllanCurve> cs;
    for (const auto& acc : s.acc) cs.push_back(acc.finish(out.meta.rate_hz));
    out.curves.push_back(std::move(cs));
  }
  std::vector<std::string> names;
  std::vector<BlockMeans> means;
  for (std::size_t c = 0; c < sinks.size(); ++c) {
    if (!sinks[c].seconds) continue;
    names.push_back(out.meta.channels[c].name);
    means.push_back(*sinks[c].seconds);
  }
  if (!means.empty()) out.warnings = motion_warnings(names, means, watch_rate_hz);
  return out;
}

}  // namespace driftless::cli::allan
