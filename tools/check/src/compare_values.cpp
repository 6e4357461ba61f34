// rbsim check's lockstep walker: two CDR messages compared value by value straight from their
// bytes, through the one CDR cursor (msgs::CdrCursor: XCDR1, little endian, alignment relative to
// the end of the 4-byte header), with no decoding, allocation or string per value.
#include "compare_values.hpp"

#include <cstring>
#include <limits>
#include <string_view>

#include "rbsim/cdr.hpp"
#include "sentences.hpp"

namespace rbsim::check {

namespace {

using msgs::CdrCursor;
using msgs::Scalar;
using Kind = Scalar::Kind;

// Walks a run message (a) and a golden message (b) in lockstep, comparing every value as it goes.
// Stops at the first differing sequence length (the layouts part) or at data that does not fit
// the schema; `index` then counts the values compared, in the decoder's scalar order.
struct Lockstep {
  Values& c;
  Tally& t;
  const std::string& topic;
  const msgs::MessageDecoder& decoder;  // the golden's, for metadata paths
  std::span<const std::byte> golden;
  CdrCursor a, b;
  std::uint64_t index = 0;
  std::uint64_t first_bad = UINT64_MAX;
  Scalar bad_a{}, bad_b{};  // the values at first_bad (run, golden), for the divergence report
  bool has_step = false;
  std::uint64_t step = 0;
  std::uint64_t budget = 0;

  static Scalar load(const std::byte* p, std::uint8_t size, Kind kind) {
    return msgs::load_scalar(p, size, kind);
  }
  // Bit-equal values (floats: equal as numbers, so 0 == -0), the common case and the only one
  // that needs no more work than counting. Pairs that fail this go to mismatch().
  static bool same(const std::byte* x, const std::byte* y, std::uint8_t size, Kind kind) {
    if (kind == Kind::Float) {
      if (size == 8) return CdrCursor::load<double>(x) == CdrCursor::load<double>(y);
      return CdrCursor::load<float>(x) == CdrCursor::load<float>(y);
    }
    switch (size) {
      case 1:
        return *x == *y;
      case 2:
        return CdrCursor::load<std::uint16_t>(x) == CdrCursor::load<std::uint16_t>(y);
      case 4:
        return CdrCursor::load<std::uint32_t>(x) == CdrCursor::load<std::uint32_t>(y);
      case 8:
        return CdrCursor::load<std::uint64_t>(x) == CdrCursor::load<std::uint64_t>(y);
      default:
        return std::memcmp(x, y, size) == 0;
    }
  }
  bool metadata(std::uint32_t group, const Scalar& run, const Scalar& golden_value) {
    return t.has_meta && c.metadata(t, topic, decoder, group, index, run, golden_value, golden);
  }
  // mismatch() for float64 values va != vb at x and y, inline: the hot case of a check in which
  // every value moved (another compiler or machine, compared with a tolerance).
  void float_mismatch(const std::byte* x, const std::byte* y, double va, double vb, std::uint32_t group,
                      std::uint64_t at) {
    if (va != va && vb != vb) return;
    index = at;
    if (t.has_meta) return mismatch(x, y, 8, Kind::Float, group);
    if (!c.differs_float(t.stats[group], va, vb) && first_bad == UINT64_MAX)
      mark(float_scalar(va), float_scalar(vb));
  }
  // A value pair (value number `index`, already counted) that same() found not equal: NaN pairs
  // match, metadata is reported apart, anything else is a difference (within the tolerance or not).
  [[gnu::noinline]] void mismatch(const std::byte* x, const std::byte* y, std::uint8_t size, Kind kind,
                                  std::uint32_t group) {
    Stat& st = t.stats[group];
    if (kind == Kind::Float) {
      double va, vb;
      if (size == 8) {
        va = CdrCursor::load<double>(x);
        vb = CdrCursor::load<double>(y);
      } else {
        va = CdrCursor::load<float>(x);
        vb = CdrCursor::load<float>(y);
      }
      if (!(va == vb || (va != va && vb != vb)) && !metadata(group, float_scalar(va), float_scalar(vb)) &&
          !c.differs_float(st, va, vb) && first_bad == UINT64_MAX) {
        mark(float_scalar(va), float_scalar(vb));
      }
      return;
    }
    const Scalar sa = load(x, size, kind), sb = load(y, size, kind);
    if (!metadata(group, sa, sb) && !c.differs(st, sa, sb) && first_bad == UINT64_MAX) mark(sa, sb);
  }
  static Scalar float_scalar(double v) {
    Scalar s;
    s.kind = Kind::Float;
    s.f = v;
    return s;
  }
  void mark(const Scalar& run_value, const Scalar& golden_value) {
    first_bad = index;
    bad_a = run_value;
    bad_b = golden_value;
  }

  Walk fields(const std::vector<Layout::Field>& fs, bool root) {
    using Array = Layout::Field::Array;
    for (const Layout::Field& f : fs) {
      std::uint64_t count = 1;
      if (f.array == Array::Sequence) {
        std::uint32_t na = 0, nb = 0;
        if (!a.u32(na) || !b.u32(nb)) return Walk::Malformed;
        if (na > a.remaining() || nb > b.remaining()) return Walk::Malformed;
        if (na != nb) return Walk::Mismatch;
        ++t.stats[f.length_group].values;
        ++index;
        count = na;
      } else if (f.array == Array::Fixed) {
        count = f.fixed;
      }
      if (count > budget) return Walk::Malformed;
      budget -= count;
      if (f.primitive && f.size > 0) {
        if (count == 0) continue;
        if (!a.align(f.size, count) || !b.align(f.size, count)) return Walk::Malformed;
        if (root && f.array == Array::None && f.name == msgs::kStepField) {
          has_step = true;
          step = step_value(load(b.here(), f.size, f.kind));
        }
        t.stats[f.group].values += count;
        for (std::uint64_t k = 0; k < count; ++k, a.advance(f.size), b.advance(f.size), ++index) {
          if (!same(a.here(), b.here(), f.size, f.kind))
            mismatch(a.here(), b.here(), f.size, f.kind, f.group);
        }
      } else if (f.primitive) {  // strings
        for (std::uint64_t k = 0; k < count; ++k) {
          Scalar x, y;
          x.kind = y.kind = Kind::String;
          if (!a.string(x.s) || !b.string(y.s)) return Walk::Malformed;
          Stat& st = t.stats[f.group];
          ++st.values;
          if (x.s != y.s && !metadata(f.group, x, y) && !c.differs(st, x, y) && first_bad == UINT64_MAX)
            mark(x, y);
          ++index;
        }
      } else if (f.flat) {
        if (const Walk w = flat(f, count); w != Walk::Ok) return w;
      } else {
        for (std::uint64_t k = 0; k < count; ++k) {
          if (const Walk w = fields(f.children, false); w != Walk::Ok) return w;
        }
      }
    }
    return Walk::Ok;
  }

  // The hot loop of a large message (bodies[], springs[]): `count` elements of a flat type, whose
  // values are counted per element after the loop (flat_groups), each pair tested for equality
  // inline.
  [[gnu::always_inline]] Walk flat(const Layout::Field& f, std::uint64_t count) {
    std::uint64_t k = 0;
    Walk w = Walk::Ok;
    std::uint64_t at = index;  // the value number, kept out of memory in the loop
    // differs_float() spelled out for float64 pairs outside metadata: one NaN test on the
    // difference (NaN only when either value is NaN, as va != vb), the tolerance in locals.
    const bool plain = !t.has_meta;
    const double atol = c.atol(), rtol = c.rtol();
    Stat* const stats = t.stats.data();
    for (; k < count; ++k) {
      const std::size_t ra = a.offset() % 8, rb = b.offset() % 8;
      if (f.flat_size[ra] > a.remaining() || f.flat_size[rb] > b.remaining()) {
        w = Walk::Malformed;
        break;
      }
      const Layout::Op* ops_a = f.flat_ops[ra].data();
      const Layout::Op* ops_b = f.flat_ops[rb].data();
      const std::size_t n = f.flat_ops[rb].size();
      const std::byte* xa = a.here();
      const std::byte* yb = b.here();
      for (std::size_t o = 0; o < n; ++o) {
        const Layout::Op& op = ops_b[o];
        const std::byte* x = xa + ops_a[o].offset;
        const std::byte* y = yb + op.offset;
        if (op.kind == Kind::Float && op.size == 8) {
          const double va = CdrCursor::load<double>(x);
          const double vb = CdrCursor::load<double>(y);
          if (va == vb) continue;
          if (!plain) {
            float_mismatch(x, y, va, vb, op.group, at + o);
            continue;
          }
          double d = std::fabs(va - vb);
          if (d != d) {
            if (va != va && vb != vb) continue;  // both NaN: a match
            d = std::numeric_limits<double>::infinity();
          }
          const double ab = std::fabs(vb);
          const double rel = vb != 0.0 ? d / ab : std::numeric_limits<double>::infinity();
          if (!c.record(stats[op.group], d, rel, d <= atol + rtol * ab) && first_bad == UINT64_MAX) {
            index = at + o;
            mark(float_scalar(va), float_scalar(vb));
          }
        } else if (!same(x, y, op.size, op.kind)) {
          index = at + o;
          mismatch(x, y, op.size, op.kind, op.group);
        }
      }
      at += n;
      a.advance(f.flat_size[ra]);
      b.advance(f.flat_size[rb]);
    }
    index = at;
    for (const auto& [g, n] : f.flat_groups) t.stats[g].values += n * k;
    return w;
  }
};

}  // namespace

bool Values::metadata(Tally& t, const std::string& topic, const msgs::MessageDecoder& golden_decoder,
                      std::uint32_t group, std::uint64_t index, const Scalar& run, const Scalar& golden,
                      std::span<const std::byte> golden_cdr) {
  if (!t.meta[group]) return false;
  if (!t.meta_reported[group]) {
    t.meta_reported[group] = 1;
    metadata_differences.push_back(
        metadata_difference(topic, golden_decoder.path(golden_cdr, index), golden, run));
  }
  return !o_.strict_metadata;
}

std::string difference(const Scalar& a, const Scalar& b) {
  switch (b.kind) {
    case Kind::Float:
      return fmt_short(a.f - b.f);
    case Kind::Int:
      return std::to_string(static_cast<long long>(a.i) - static_cast<long long>(b.i));
    case Kind::UInt:
    case Kind::Length:
      return a.u >= b.u ? std::to_string(a.u - b.u) : "-" + std::to_string(b.u - a.u);
    case Kind::Bool:
    case Kind::String:
      return "differs";
  }
  return "differs";
}

WalkResult lockstep(Values& values, const Layout& layout, Tally& tally, const std::string& topic,
                    const msgs::MessageDecoder& golden_decoder, std::span<const std::byte> run,
                    std::span<const std::byte> golden) {
  WalkResult r;
  if (!CdrCursor::plain_header(run) || !CdrCursor::plain_header(golden)) return r;
  Lockstep ls{values, tally, topic, golden_decoder, golden, CdrCursor(run), CdrCursor(golden)};
  ls.budget = 4 * static_cast<std::uint64_t>(run.size() + golden.size()) + 1024;
  r.walk = ls.fields(layout.root(), true);
  r.index = ls.index;
  r.first_bad = ls.first_bad;
  r.bad_a = ls.bad_a;
  r.bad_b = ls.bad_b;
  r.has_step = ls.has_step;
  r.step = ls.step;
  return r;
}

}  // namespace rbsim::check
