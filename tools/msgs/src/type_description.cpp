// CDR codecs of type_description_interfaces (rbsim/type_description.hpp), on the one codec skeleton.
#include "rbsim/type_description.hpp"

#include "interface_codec.hpp"

namespace rbsim::msgs {

using detail::CdrWriter;
using detail::Reader;

namespace {

using detail::kMinString;

// The fewest bytes an element of each sequence takes before padding (see kMinString): a huge
// length in a short message fails before anything is allocated.
constexpr std::size_t kMinFieldType = 1 + 8 + 8 + kMinString;
constexpr std::size_t kMinField = kMinString + kMinFieldType + kMinString;
constexpr std::size_t kMinIndividual = kMinString + 4;
constexpr std::size_t kMinTypeSource = 3 * kMinString;
constexpr std::size_t kMinKeyValue = 2 * kMinString;

// A string<=255 of the definitions: longer is malformed, as a DDS reader refuses it.
std::string bounded_string(Reader& r) {
  std::string s = r.string();
  if (s.size() > FieldType::kMaxNameLength) r.fail();
  return s;
}

template <class T, class Get>
void get_sequence(Reader& r, std::vector<T>& v, std::size_t min_size, Get get_one) {
  v.resize(r.length(min_size));
  for (T& x : v) get_one(r, x);
}
template <class T, class Put>
void put_sequence(CdrWriter& w, const std::vector<T>& v, Put put_one) {
  w.sequence_length(v.size());
  for (const T& x : v) put_one(w, x);
}

void put(CdrWriter& w, const Field& m) {
  w.string(m.name);
  w.u8(m.type.type_id);
  w.u64(m.type.capacity);
  w.u64(m.type.string_capacity);
  w.string(m.type.nested_type_name);
  w.string(m.default_value);
}
void get(Reader& r, Field& m) {
  m.name = r.string();
  m.type.type_id = r.get<std::uint8_t>();
  m.type.capacity = r.get<std::uint64_t>();
  m.type.string_capacity = r.get<std::uint64_t>();
  m.type.nested_type_name = bounded_string(r);
  m.default_value = r.string();
}
void put(CdrWriter& w, const IndividualTypeDescription& m) {
  w.string(m.type_name);
  put_sequence(w, m.fields, [](CdrWriter& ww, const Field& f) { put(ww, f); });
}
void get(Reader& r, IndividualTypeDescription& m) {
  m.type_name = bounded_string(r);
  get_sequence(r, m.fields, kMinField, [](Reader& rr, Field& f) { get(rr, f); });
}
void put(CdrWriter& w, const TypeDescription& m) {
  put(w, m.type_description);
  put_sequence(w, m.referenced_type_descriptions,
               [](CdrWriter& ww, const IndividualTypeDescription& d) { put(ww, d); });
}
void get(Reader& r, TypeDescription& m) {
  get(r, m.type_description);
  get_sequence(r, m.referenced_type_descriptions, kMinIndividual,
               [](Reader& rr, IndividualTypeDescription& d) { get(rr, d); });
}
void put(CdrWriter& w, const TypeSource& m) {
  w.string(m.type_name);
  w.string(m.encoding);
  w.string(m.raw_file_contents);
}
void get(Reader& r, TypeSource& m) {
  m.type_name = r.string();
  m.encoding = r.string();
  m.raw_file_contents = r.string();
}
void put(CdrWriter& w, const GetTypeDescriptionRequest& m) {
  w.string(m.type_name);
  w.string(m.type_hash);
  w.boolean(m.include_type_sources);
}
void get(Reader& r, GetTypeDescriptionRequest& m) {
  m.type_name = r.string();
  m.type_hash = r.string();
  m.include_type_sources = r.get<std::uint8_t>() != 0;
}
void put(CdrWriter& w, const GetTypeDescriptionResponse& m) {
  w.boolean(m.successful);
  w.string(m.failure_reason);
  put(w, m.type_description);
  put_sequence(w, m.type_sources, [](CdrWriter& ww, const TypeSource& s) { put(ww, s); });
  put_sequence(w, m.extra_information, [](CdrWriter& ww, const KeyValue& kv) {
    ww.string(kv.key);
    ww.string(kv.value);
  });
}
void get(Reader& r, GetTypeDescriptionResponse& m) {
  m.successful = r.get<std::uint8_t>() != 0;
  m.failure_reason = r.string();
  get(r, m.type_description);
  get_sequence(r, m.type_sources, kMinTypeSource, [](Reader& rr, TypeSource& s) { get(rr, s); });
  get_sequence(r, m.extra_information, kMinKeyValue, [](Reader& rr, KeyValue& kv) {
    kv.key = rr.string();
    kv.value = rr.string();
  });
}

}  // namespace

RBSIM_DEFINE_CODEC(TypeDescription, "")
RBSIM_DEFINE_CODEC(TypeSource, "")
RBSIM_DEFINE_CODEC(GetTypeDescriptionRequest, " request")
RBSIM_DEFINE_CODEC(GetTypeDescriptionResponse, " response")

}  // namespace rbsim::msgs
