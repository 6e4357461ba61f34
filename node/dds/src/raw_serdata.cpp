#include "raw_serdata.hpp"

#include <dds/ddsi/ddsi_sertype.h>
#include <dds/ddsi/q_radmin.h>

#include <algorithm>
#include <cstdint>
#include <cstring>

namespace rbsim::node {

namespace {

struct RawSerdata {
  ddsi_serdata c;  // first: Cyclone sees a ddsi_serdata*
  std::uint32_t size;
  unsigned char* bytes;  // size rounded up to 4, zero padded
};
const RawSerdata& raw(const ddsi_serdata* d) {
  return *reinterpret_cast<const RawSerdata*>(d);
}
void free_serdata(ddsi_serdata* d) {
  auto* r = reinterpret_cast<RawSerdata*>(d);
  delete[] r->bytes;
  delete r;
}

RawSerdata* make(const ddsi_sertype* type, ddsi_serdata_kind kind, std::size_t size) {
  auto* d = new RawSerdata{};
  ddsi_serdata_init(&d->c, type, kind);
  d->c.hash = type->serdata_basehash;  // keyless: every sample is the one instance
  d->size = static_cast<std::uint32_t>(size);
  const std::size_t padded = (size + 3) / 4 * 4;
  d->bytes = new unsigned char[padded];
  std::memset(d->bytes + size, 0, padded - size);
  return d;
}

// A received sample: its fragments, in order, each covering [min, maxp1) of the payload and
// possibly overlapping the one before (Cyclone's own serdata reads them the same way). The
// bytes are kept as they came: rbsim's decoders check what they read.
ddsi_serdata* from_ser(const ddsi_sertype* type, ddsi_serdata_kind kind, const nn_rdata* fragchain,
                       std::size_t size) {
  RawSerdata* d = make(type, kind, size);
  std::size_t off = 0;
  for (const nn_rdata* f = fragchain; f != nullptr && off < size; f = f->nextfrag) {
    if (f->min > off || f->maxp1 > size) break;  // a gap or an overrun: never from Cyclone
    if (f->maxp1 <= off) continue;
    const unsigned char* payload = NN_RMSG_PAYLOADOFF(f->rmsg, NN_RDATA_PAYLOAD_OFF(f));
    std::memcpy(d->bytes + off, payload + (off - f->min), f->maxp1 - off);
    off = f->maxp1;
  }
  if (off < size) {
    free_serdata(&d->c);
    return nullptr;
  }
  return &d->c;
}

ddsi_serdata* from_ser_iov(const ddsi_sertype* type, ddsi_serdata_kind kind, ddsrt_msg_iovlen_t niov,
                           const ddsrt_iovec_t* iov, std::size_t size) {
  RawSerdata* d = make(type, kind, size);
  std::size_t at = 0;
  for (ddsrt_msg_iovlen_t i = 0; i < niov && at < size; ++i) {
    const std::size_t n = std::min<std::size_t>(iov[i].iov_len, size - at);
    std::memcpy(d->bytes + at, iov[i].iov_base, n);
    at += n;
  }
  if (at < size) std::memset(d->bytes + at, 0, size - at);
  return &d->c;
}
std::uint32_t get_size(const ddsi_serdata* d) {
  return raw(d).size;
}
void to_ser(const ddsi_serdata* d, std::size_t off, std::size_t sz, void* buf) {
  std::memcpy(buf, raw(d).bytes + off, sz);
}
ddsi_serdata* to_ser_ref(const ddsi_serdata* d, std::size_t off, std::size_t sz, ddsrt_iovec_t* ref) {
  ref->iov_base = raw(d).bytes + off;
  ref->iov_len = sz;
  return ddsi_serdata_ref(d);
}
void to_ser_unref(ddsi_serdata* d, const ddsrt_iovec_t*) {
  ddsi_serdata_unref(d);
}
bool eqkey(const ddsi_serdata*, const ddsi_serdata*) {
  return true;
}  // keyless topics
bool to_sample(const ddsi_serdata*, void*, void**, void*) {
  return false;
}
ddsi_serdata* to_untyped(const ddsi_serdata* d) {
  return ddsi_serdata_ref(d);
}
bool untyped_to_sample(const ddsi_sertype*, const ddsi_serdata*, void*, void**, void*) {
  return false;
}
std::size_t print(const ddsi_sertype*, const ddsi_serdata*, char* buf, std::size_t size) {
  if (size > 0) buf[0] = 0;
  return 0;
}
void get_keyhash(const ddsi_serdata*, ddsi_keyhash* buf, bool) {
  std::memset(buf, 0, sizeof *buf);
}

const ddsi_serdata_ops kSerdataOps = [] {
  ddsi_serdata_ops ops{};
  ops.eqkey = eqkey;
  ops.get_size = get_size;
  ops.from_ser = from_ser;
  ops.from_ser_iov = from_ser_iov;
  ops.to_ser = to_ser;
  ops.to_ser_ref = to_ser_ref;
  ops.to_ser_unref = to_ser_unref;
  ops.to_sample = to_sample;
  ops.to_untyped = to_untyped;
  ops.untyped_to_sample = untyped_to_sample;
  ops.free = free_serdata;
  ops.print = print;
  ops.get_keyhash = get_keyhash;
  return ops;
}();

void sertype_free(ddsi_sertype* t) {
  ddsi_sertype_fini(t);
  delete t;
}
void zero_samples(const ddsi_sertype*, void*, std::size_t) {}
void realloc_samples(void** ptrs, const ddsi_sertype*, void*, std::size_t, std::size_t) {
  *ptrs = nullptr;
}
void free_samples(const ddsi_sertype*, void**, std::size_t, dds_free_op_t) {}
// Cyclone compares the ops and type names before this: raw types of one name are one type.
bool sertype_equal(const ddsi_sertype*, const ddsi_sertype*) {
  return true;
}
std::uint32_t sertype_hash(const ddsi_sertype*) {
  return 0;
}

const ddsi_sertype_ops kSertypeOps = [] {
  ddsi_sertype_ops ops{};
  ops.version = ddsi_sertype_v0;
  ops.free = sertype_free;
  ops.zero_samples = zero_samples;
  ops.realloc_samples = realloc_samples;
  ops.free_samples = free_samples;
  ops.equal = sertype_equal;
  ops.hash = sertype_hash;
  return ops;
}();

}  // namespace

ddsi_sertype* make_raw_sertype(const char* type_name) {
  auto* t = new ddsi_sertype{};
  ddsi_sertype_init(t, type_name, &kSertypeOps, &kSerdataOps, /*topickind_no_key=*/true);
  return t;
}

ddsi_serdata* make_raw_serdata(const ddsi_sertype* type, std::span<const std::byte> cdr) {
  ddsrt_iovec_t iov;
  iov.iov_base = const_cast<std::byte*>(cdr.data());
  iov.iov_len = static_cast<ddsrt_iov_len_t>(cdr.size());
  return ddsi_serdata_from_ser_iov(type, SDK_DATA, 1, &iov, cdr.size());
}

Result<dds_entity_t> make_raw_topic(dds_entity_t participant, const std::string& name,
                                    const std::string& type_name, const ddsi_sertype** sertype) {
  ddsi_sertype* type = make_raw_sertype(type_name.c_str());
  const dds_entity_t topic =
      dds_create_topic_sertype(participant, name.c_str(), &type, nullptr, nullptr, nullptr);
  if (topic < 0) {
    ddsi_sertype_unref(type);  // not taken over on failure
    return dds_error("cannot create DDS topic " + name, topic);
  }
  if (sertype != nullptr) *sertype = type;
  return topic;
}

Error dds_error(const std::string& what, dds_return_t rc) {
  return Error{what + ": " + dds_strretcode(rc)};
}

}  // namespace rbsim::node
