#include "raw_serdata.hpp"

#include <dds/ddsi/ddsi_sertype.h>

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

ddsi_serdata* from_ser_iov(const ddsi_sertype* type, ddsi_serdata_kind kind, ddsrt_msg_iovlen_t niov,
                           const ddsrt_iovec_t* iov, std::size_t size) {
  auto* d = new RawSerdata{};
  ddsi_serdata_init(&d->c, type, kind);
  d->size = static_cast<std::uint32_t>(size);
  d->bytes = new unsigned char[(size + 3) / 4 * 4]();
  std::size_t at = 0;
  for (ddsrt_msg_iovlen_t i = 0; i < niov && at < size; ++i) {
    const std::size_t n = std::min<std::size_t>(iov[i].iov_len, size - at);
    std::memcpy(d->bytes + at, iov[i].iov_base, n);
    at += n;
  }
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
void free_serdata(ddsi_serdata* d) {
  auto* r = reinterpret_cast<RawSerdata*>(d);
  delete[] r->bytes;
  delete r;
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

void sertype_free(ddsi_sertype*) {}
void zero_samples(const ddsi_sertype*, void*, std::size_t) {}
void realloc_samples(void** ptrs, const ddsi_sertype*, void*, std::size_t, std::size_t) {
  *ptrs = nullptr;
}
void free_samples(const ddsi_sertype*, void**, std::size_t, dds_free_op_t) {}
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

// One process-wide, never registered with a domain: it only tags serdata as raw bytes.
const ddsi_sertype* raw_sertype() {
  static ddsi_sertype type = [] {
    ddsi_sertype t{};
    ddsi_sertype_init(&t, "rbsim::raw_cdr", &kSertypeOps, &kSerdataOps, /*topickind_no_key=*/true);
    return t;
  }();
  return &type;
}

}  // namespace

ddsi_serdata* make_raw_serdata(std::span<const std::byte> cdr) {
  ddsrt_iovec_t iov;
  iov.iov_base = const_cast<std::byte*>(cdr.data());
  iov.iov_len = static_cast<ddsrt_iov_len_t>(cdr.size());
  return ddsi_serdata_from_ser_iov(raw_sertype(), SDK_DATA, 1, &iov, cdr.size());
}

}  // namespace rbsim::node
