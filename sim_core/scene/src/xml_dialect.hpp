#pragma once
#include <string>
#include <string_view>

#include "rbsim/core.hpp"

namespace rbsim {

// Suffix given to the 2nd, 3rd, ... occurrence of an attribute within one start tag.
inline constexpr std::string_view kDuplicateMark = "-rbsim-dup-";

// FOSSSim scenes repeat attributes (<rigidbody p="0" p="1" .../>), which is not well-formed
// XML and which tinyxml2 rejects. This rewrites the k-th repeat of a name within a start tag to
// "<name>-rbsim-dup-<k>" (a valid XML name), touching nothing else: no newline is added or
// removed, so line numbers in later error messages stay those of the original file. Text that
// does not scan as markup is copied unchanged for the XML parser to report.
// Fails ("<line>: ...") on a start tag with more than kMaxAttributes attributes: tinyxml2's
// duplicate check is quadratic in the attribute count, and no real hull is that large.
inline constexpr std::size_t kMaxAttributes = 4096;
Result<std::string> rename_repeated_attributes(std::string_view text);

// "p-rbsim-dup-3" -> "p"; any other name is returned as is.
std::string_view original_attribute_name(std::string_view name);

}  // namespace rbsim
