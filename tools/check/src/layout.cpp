// The layout walker of rbsim check: a ros2msg schema expanded into field groups, and CDR messages
// walked against it (values counted or paired without decoding them all).
#include <algorithm>
#include <map>
#include <string_view>
#include <utility>

#include "layout.hpp"
#include "rbsim/cdr.hpp"

namespace rbsim::check {

// ---------------------------------------------------------------------------------------------
// Layout: the schema parsed by msgs::MessageDecoder's rules, expanded into field groups.

namespace {

using msgs::canonical_type;

// Bytes a run of fixed-size fields takes from offset `at` (relative to the data start).
std::uint64_t flat_bytes(const std::vector<Layout::Field>& fields, std::uint64_t at) {
  const std::uint64_t start = at;
  for (const Layout::Field& f : fields) {
    const std::uint64_t count = f.array == Layout::Field::Array::Fixed ? f.fixed : 1;
    for (std::uint64_t k = 0; k < count; ++k) {
      if (f.primitive) {
        at += (f.size - at % f.size) % f.size + f.size;
      } else {
        at += f.flat_size[at % 8];
      }
    }
  }
  return at - start;
}

// The values one element of a flat type holds when it starts at offset `at`, in order.
void flat_ops(const std::vector<Layout::Field>& fields, std::uint64_t& at, std::uint64_t start,
              std::vector<Layout::Op>& out) {
  for (const Layout::Field& f : fields) {
    const std::uint64_t count = f.array == Layout::Field::Array::Fixed ? f.fixed : 1;
    for (std::uint64_t k = 0; k < count; ++k) {
      if (f.primitive) {
        at += (f.size - at % f.size) % f.size;
        out.push_back({static_cast<std::uint32_t>(at - start), f.size, f.kind, f.group});
        at += f.size;
      } else {
        flat_ops(f.children, at, start, out);
      }
    }
  }
}

void make_flat(Layout::Field& f) {
  f.flat = true;
  std::map<std::uint32_t, std::uint64_t> groups;
  for (const Layout::Field& c : f.children) {
    const std::uint64_t count = c.array == Layout::Field::Array::Fixed ? c.fixed : 1;
    if (c.array == Layout::Field::Array::Sequence || (c.primitive && c.size == 0) ||
        (!c.primitive && !c.flat) || count > 4096) {
      f.flat = false;
      return;
    }
    if (c.primitive) {
      groups[c.group] += count;
    } else {
      for (const auto& [g, n] : c.flat_groups) groups[g] += n * count;
    }
  }
  for (std::uint64_t r = 0; r < 8; ++r) {
    const std::uint64_t bytes = flat_bytes(f.children, r);
    if (bytes > UINT32_MAX) {
      f.flat = false;
      return;
    }
    f.flat_size[r] = static_cast<std::uint32_t>(bytes);
    std::uint64_t at = r;
    f.flat_ops[r].clear();
    flat_ops(f.children, at, r, f.flat_ops[r]);
  }
  f.flat_groups.assign(groups.begin(), groups.end());
}

class LayoutBuilder {
 public:
  explicit LayoutBuilder(std::string_view schema, const std::string& root)
      : sections_(msgs::schema_sections(root, schema)) {}

  Result<std::vector<Layout::Field>> expand(const std::string& type, const std::string& prefix, int depth,
                                            std::vector<FieldGroup>& groups) {
    if (depth > 64) return Error{"types nest deeper than 64"};
    const auto section = sections_.find(type);
    if (section == sections_.end()) return Error{"schema has no definition for " + type};
    Result<std::vector<msgs::MsgField>> raw = msgs::parse_msg_fields(type, section->second);
    if (!raw) return raw.error();
    std::vector<Layout::Field> out;
    for (const msgs::MsgField& rf : raw.value()) {
      if (groups.size() > 100000) return Error{"schema expands to more than 100000 fields"};
      Layout::Field f;
      f.name = rf.name;
      f.array = rf.array;
      f.fixed = rf.fixed_size;
      const std::string path = prefix.empty() ? rf.name : prefix + "." + rf.name;
      if (f.array == Layout::Field::Array::Sequence) {
        f.length_group = static_cast<std::uint32_t>(groups.size());
        groups.push_back({path + ".length", msgs::Scalar::Kind::Length});
      }
      const std::string element = f.array == Layout::Field::Array::None ? path : path + "[]";
      if (rf.primitive) {
        f.primitive = true;
        f.kind = rf.primitive->kind;
        f.size = rf.primitive->size;
        f.group = static_cast<std::uint32_t>(groups.size());
        groups.push_back({element, f.kind});
      } else {
        auto children = expand(rf.type, element, depth + 1, groups);
        if (!children) return children.error();
        f.children = std::move(children.value());
        make_flat(f);
      }
      out.push_back(std::move(f));
    }
    return out;
  }

 private:
  std::map<std::string, std::string> sections_;
};

// Walks the scalars of one message along the fields; `plan` may be null (skipping an element).
// `budget` bounds the elements visited, so no schema can make the walk run away.
bool walk(const std::vector<Layout::Field>& fields, std::span<const msgs::Scalar> s, std::size_t& pos,
          Plan* plan, bool root, std::uint64_t& budget) {
  using Array = Layout::Field::Array;
  for (const Layout::Field& f : fields) {
    std::uint64_t count = 1;
    if (f.array == Array::Sequence) {
      if (pos >= s.size() || s[pos].kind != msgs::Scalar::Kind::Length) return false;
      count = s[pos].u;
      if (plan != nullptr) {
        plan->group.push_back(f.length_group);
        plan->lengths.emplace_back(static_cast<std::uint32_t>(pos), count);
      }
      ++pos;
    } else if (f.array == Array::Fixed) {
      count = f.fixed;
    }
    if (count > budget) return false;
    budget -= count;
    if (f.primitive) {
      if (count > s.size() - pos) return false;
      for (std::uint64_t k = 0; k < count; ++k, ++pos) {
        if (s[pos].kind != f.kind) return false;
        if (plan != nullptr) {
          if (root && f.array == Array::None && f.name == msgs::kStepField)
            plan->step = static_cast<std::ptrdiff_t>(pos);
          plan->group.push_back(f.group);
        }
      }
    } else {
      for (std::uint64_t k = 0; k < count; ++k) {
        if (!walk(f.children, s, pos, plan, false, budget)) return false;
      }
    }
  }
  return true;
}

struct Pairer {
  std::span<const msgs::Scalar> a, b;
  std::size_t pa = 0, pb = 0;
  std::vector<Pair>* out;
  std::uint64_t budget;

  bool fields(const std::vector<Layout::Field>& fs) {
    using Array = Layout::Field::Array;
    for (const Layout::Field& f : fs) {
      std::uint64_t ca = 1, cb = 1;
      if (f.array == Array::Sequence) {
        if (pa >= a.size() || pb >= b.size() || a[pa].kind != msgs::Scalar::Kind::Length ||
            b[pb].kind != msgs::Scalar::Kind::Length) {
          return false;
        }
        ca = a[pa].u;
        cb = b[pb].u;
        out->push_back({pa++, pb++, f.length_group});
      } else if (f.array == Array::Fixed) {
        ca = cb = f.fixed;
      }
      if (ca > budget || cb > budget - ca) return false;
      budget -= ca + cb;
      const std::uint64_t common = std::min(ca, cb);
      if (f.primitive) {
        if (ca > a.size() - pa || cb > b.size() - pb) return false;
        for (std::uint64_t k = 0; k < common; ++k) {
          if (a[pa].kind != f.kind || b[pb].kind != f.kind) return false;
          out->push_back({pa++, pb++, f.group});
        }
        pa += static_cast<std::size_t>(ca - common);
        pb += static_cast<std::size_t>(cb - common);
      } else {
        for (std::uint64_t k = 0; k < common; ++k) {
          if (!fields(f.children)) return false;
        }
        for (std::uint64_t k = common; k < ca; ++k) {
          if (!walk(f.children, a, pa, nullptr, false, budget)) return false;
        }
        for (std::uint64_t k = common; k < cb; ++k) {
          if (!walk(f.children, b, pb, nullptr, false, budget)) return false;
        }
      }
    }
    return true;
  }
};

// Walks CDR bytes through the one CDR cursor (the decoders' rules), reading only lengths.
struct ByteCounter {
  msgs::CdrCursor at;
  std::vector<std::uint64_t>& counts;
  std::uint64_t budget;

  bool fields(const std::vector<Layout::Field>& fs) {
    using Array = Layout::Field::Array;
    for (const Layout::Field& f : fs) {
      std::uint64_t count = 1;
      if (f.array == Array::Sequence) {
        std::uint32_t n = 0;
        if (!at.u32(n) || n > at.remaining()) return false;
        ++counts[f.length_group];
        count = n;
      } else if (f.array == Array::Fixed) {
        count = f.fixed;
      }
      if (count > budget) return false;
      budget -= count;
      if (f.primitive) {
        counts[f.group] += count;
        if (f.size > 0) {
          if (count > 0 && !at.skip(f.size, count)) return false;
        } else {
          std::string_view s;
          for (std::uint64_t k = 0; k < count; ++k) {
            if (!at.string(s)) return false;
          }
        }
      } else if (f.flat) {
        for (std::uint64_t k = 0; k < count; ++k) {
          const std::size_t bytes = f.flat_size[at.offset() % 8];
          if (bytes > at.remaining()) return false;
          at.advance(bytes);
        }
        for (const auto& [g, n] : f.flat_groups) counts[g] += n * count;
      } else {
        for (std::uint64_t k = 0; k < count; ++k) {
          if (!fields(f.children)) return false;
        }
      }
    }
    return true;
  }
};

}  // namespace

bool Layout::count(std::span<const std::byte> cdr, std::vector<std::uint64_t>& counts) const {
  if (!msgs::CdrCursor::plain_header(cdr)) return false;
  if (counts.size() < groups_.size()) counts.resize(groups_.size(), 0);
  ByteCounter c{msgs::CdrCursor(cdr), counts, 4 * static_cast<std::uint64_t>(cdr.size()) + 1024};
  return c.fields(root_);
}

Result<Layout> Layout::create(std::string_view type, std::string_view schema) {
  const std::string root = canonical_type(type, "");
  LayoutBuilder builder(schema, root);
  Layout layout;
  auto fields = builder.expand(root, "", 0, layout.groups_);
  if (!fields) return fields.error();
  layout.root_ = std::move(fields.value());
  for (const Field& f : layout.root_) {
    if (f.name == msgs::kStepField && f.primitive && f.array == Field::Array::None &&
        (f.kind == msgs::Scalar::Kind::UInt || f.kind == msgs::Scalar::Kind::Int)) {
      layout.has_step_ = true;
    }
  }
  return layout;
}

bool Layout::map(std::span<const msgs::Scalar> s, Plan& plan) const {
  plan.group.clear();
  plan.lengths.clear();
  plan.step = -1;
  std::size_t pos = 0;
  std::uint64_t budget = 4 * static_cast<std::uint64_t>(s.size()) + 1024;
  return walk(root_, s, pos, &plan, true, budget) && pos == s.size();
}

bool Layout::pair(std::span<const msgs::Scalar> a, std::span<const msgs::Scalar> b,
                  std::vector<Pair>& out) const {
  out.clear();
  Pairer p{a, b, 0, 0, &out, 8 * static_cast<std::uint64_t>(a.size() + b.size()) + 1024};
  return p.fields(root_) && p.pa == a.size() && p.pb == b.size();
}

}  // namespace rbsim::check
