#include "xml_dialect.hpp"

#include <algorithm>
#include <string>
#include <unordered_map>

namespace rbsim {

namespace {

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}
bool is_name_char(char c) {
  return !is_space(c) && c != '=' && c != '>' && c != '/' && c != '<' && c != '"' && c != '\'';
}

// Copies text[pos..] up to and including `terminator`; returns the position after it.
std::size_t copy_through(std::string_view text, std::size_t pos, std::string_view terminator,
                         std::string& out) {
  const std::size_t end = text.find(terminator, pos);
  const std::size_t stop = end == std::string_view::npos ? text.size() : end + terminator.size();
  out.append(text.substr(pos, stop - pos));
  return stop;
}

// Rewrites one start tag beginning at text[pos] == '<'. Returns the position after the tag, or
// npos when it does not scan as a start tag (the caller then copies the rest verbatim).
std::size_t rewrite_start_tag(std::string_view text, std::size_t pos, std::string& out,
                              std::size_t& too_many) {
  std::size_t i = pos + 1;
  while (i < text.size() && is_name_char(text[i])) ++i;
  std::string tag(text.substr(pos, i - pos));
  std::unordered_map<std::string, int> seen;  // name -> occurrences so far in this tag
  std::size_t attributes = 0;
  while (true) {
    const std::size_t ws = i;
    while (i < text.size() && is_space(text[i])) ++i;
    tag.append(text.substr(ws, i - ws));
    if (i >= text.size()) return std::string_view::npos;
    if (text[i] == '>') break;
    if (text[i] == '/' && i + 1 < text.size() && text[i + 1] == '>') {
      tag += '/';
      ++i;
      break;
    }
    const std::size_t name_begin = i;
    while (i < text.size() && is_name_char(text[i])) ++i;
    if (i == name_begin) return std::string_view::npos;
    std::string name(text.substr(name_begin, i - name_begin));
    if (++attributes > kMaxAttributes) {
      too_many = pos;
      return std::string_view::npos;
    }
    const int occurrence = ++seen[name];
    if (occurrence > 1) name += std::string(kDuplicateMark) + std::to_string(occurrence);
    tag += name;
    // = "value" (whitespace allowed around '=')
    const std::size_t eq_begin = i;
    while (i < text.size() && is_space(text[i])) ++i;
    if (i >= text.size() || text[i] != '=') return std::string_view::npos;
    ++i;
    while (i < text.size() && is_space(text[i])) ++i;
    if (i >= text.size() || (text[i] != '"' && text[i] != '\'')) return std::string_view::npos;
    const std::size_t close = text.find(text[i], i + 1);
    if (close == std::string_view::npos) return std::string_view::npos;
    i = close + 1;
    tag.append(text.substr(eq_begin, i - eq_begin));
  }
  tag += '>';
  out += tag;
  return i + 1;
}

}  // namespace

Result<std::string> rename_repeated_attributes(std::string_view text) {
  std::string out;
  out.reserve(text.size() + text.size() / 8);
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t lt = text.find('<', pos);
    if (lt == std::string_view::npos) break;
    out.append(text.substr(pos, lt - pos));
    const std::string_view rest = text.substr(lt);
    if (rest.starts_with("<!--")) {
      pos = copy_through(text, lt, "-->", out);
    } else if (rest.starts_with("<![CDATA[")) {
      pos = copy_through(text, lt, "]]>", out);
    } else if (rest.starts_with("<?")) {
      pos = copy_through(text, lt, "?>", out);
    } else if (rest.starts_with("<!") || rest.starts_with("</")) {
      pos = copy_through(text, lt, ">", out);
    } else {
      std::size_t too_many = std::string_view::npos;
      const std::size_t next = rewrite_start_tag(text, lt, out, too_many);
      if (too_many != std::string_view::npos) {
        const auto line =
            1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(too_many), '\n');
        return Error{std::to_string(line) + ": a start tag has more than " + std::to_string(kMaxAttributes) +
                     " attributes (limit of the scene loader)"};
      }
      if (next == std::string_view::npos) {
        out.append(text.substr(lt));
        return out;
      }
      pos = next;
    }
  }
  out.append(text.substr(std::min(pos, text.size())));
  return out;
}

std::string_view original_attribute_name(std::string_view name) {
  const std::size_t mark = name.find(kDuplicateMark);
  return mark == std::string_view::npos ? name : name.substr(0, mark);
}

}  // namespace rbsim
