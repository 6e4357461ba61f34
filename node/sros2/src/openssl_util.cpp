// OpenSSL for DDS Security's files (rbsim/openssl_util.hpp).
#include "rbsim/openssl_util.hpp"

#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/rand.h>
#include <openssl/x509v3.h>

namespace rbsim::node::ssl {

namespace {

struct BioFree {
  void operator()(BIO* b) const { BIO_free(b); }
};
using BioPtr = std::unique_ptr<BIO, BioFree>;

Error failure(const std::string& path, const std::string& what) {
  const std::string why = last_error();
  return Error{path + ": " + what + (why.empty() ? "" : " (" + why + ")"), ErrorCode::InvalidArgument};
}

}  // namespace

std::string last_error() {
  const unsigned long e = ERR_get_error();
  ERR_clear_error();
  if (e == 0) return "";
  char buf[256];
  ERR_error_string_n(e, buf, sizeof buf);
  return buf;
}

Result<X509Ptr> read_certificate(const std::string& path) {
  BioPtr in(BIO_new_file(path.c_str(), "r"));
  if (!in) return failure(path, "cannot be read");
  X509Ptr cert(PEM_read_bio_X509(in.get(), nullptr, nullptr, nullptr));
  if (!cert) return failure(path, "not a PEM certificate");
  return cert;
}

Result<KeyPtr> read_private_key(const std::string& path) {
  BioPtr in(BIO_new_file(path.c_str(), "r"));
  if (!in) return failure(path, "cannot be read");
  KeyPtr key(PEM_read_bio_PrivateKey(in.get(), nullptr, nullptr, nullptr));
  if (!key) return failure(path, "not a PEM private key (without a passphrase)");
  return key;
}

Status verify_issued_by(X509& cert, X509& ca) {
  EVP_PKEY* ca_key = X509_get0_pubkey(&ca);
  if (ca_key == nullptr || X509_verify(&cert, ca_key) != 1) {
    last_error();
    return Error{"not signed by that CA"};
  }
  return Ok{};
}

Status verify_smime(const std::string& path, X509& ca) {
  BioPtr in(BIO_new_file(path.c_str(), "r"));
  if (!in) return failure(path, "cannot be read");
  BIO* content = nullptr;
  PKCS7* p7 = SMIME_read_PKCS7(in.get(), &content);
  BioPtr content_owner(content);
  if (p7 == nullptr) {
    last_error();
    return Error{"not an S/MIME signed document"};
  }
  X509_STORE* store = X509_STORE_new();
  X509_STORE_add_cert(store, &ca);
  const int ok = PKCS7_verify(p7, nullptr, store, content, nullptr, PKCS7_TEXT);
  X509_STORE_free(store);
  PKCS7_free(p7);
  if (ok != 1) {
    const std::string why = last_error();
    return Error{"its signature does not verify" + (why.empty() ? "" : " (" + why + ")")};
  }
  return Ok{};
}

Result<KeyPtr> generate_key() {
  KeyPtr key(EVP_EC_gen("P-256"));
  if (!key) return Error{"cannot generate an EC P-256 key: " + last_error()};
  return key;
}

Result<X509Ptr> make_certificate(const std::string& common_name, EVP_PKEY& subject_key, X509* issuer,
                                 EVP_PKEY& issuer_key) {
  X509Ptr cert(X509_new());
  unsigned char serial[16];
  if (!cert || RAND_bytes(serial, sizeof serial) != 1)
    return Error{"cannot make a certificate: " + last_error()};
  serial[0] &= 0x7f;  // a positive serial number
  BIGNUM* bn = BN_bin2bn(serial, sizeof serial, nullptr);
  BN_to_ASN1_INTEGER(bn, X509_get_serialNumber(cert.get()));
  BN_free(bn);
  X509_set_version(cert.get(), 2);
  X509_gmtime_adj(X509_getm_notBefore(cert.get()), -24L * 3600);
  X509_gmtime_adj(X509_getm_notAfter(cert.get()), 10L * 365 * 24 * 3600);
  X509_NAME* name = X509_get_subject_name(cert.get());
  X509_NAME_add_entry_by_txt(name, "CN", MBSTRING_UTF8,
                             reinterpret_cast<const unsigned char*>(common_name.c_str()), -1, -1, 0);
  X509_set_issuer_name(cert.get(), issuer != nullptr ? X509_get_subject_name(issuer) : name);
  X509_set_pubkey(cert.get(), &subject_key);
  X509V3_CTX ctx;
  X509V3_set_ctx_nodb(&ctx);
  X509V3_set_ctx(&ctx, issuer != nullptr ? issuer : cert.get(), cert.get(), nullptr, nullptr, 0);
  X509_EXTENSION* ext = X509V3_EXT_conf_nid(nullptr, &ctx, NID_basic_constraints,
                                            issuer == nullptr ? "critical,CA:TRUE,pathlen:1" : "CA:FALSE");
  X509_add_ext(cert.get(), ext, -1);
  X509_EXTENSION_free(ext);
  if (X509_sign(cert.get(), &issuer_key, EVP_sha256()) == 0)
    return Error{"cannot sign the certificate of " + common_name + ": " + last_error()};
  return cert;
}

namespace {

// What a memory BIO holds, as text.
std::string contents(BIO& bio) {
  char* data = nullptr;
  const long size = BIO_get_mem_data(&bio, &data);
  return size > 0 ? std::string(data, static_cast<std::size_t>(size)) : std::string();
}

}  // namespace

Result<std::string> certificate_pem(X509& cert, const std::string& what) {
  BioPtr out(BIO_new(BIO_s_mem()));
  if (!out || PEM_write_bio_X509(out.get(), &cert) != 1) return failure(what, "cannot be encoded");
  return contents(*out);
}

Result<std::string> private_key_pem(EVP_PKEY& key, const std::string& what) {
  BioPtr out(BIO_new(BIO_s_mem()));
  if (!out || PEM_write_bio_PrivateKey(out.get(), &key, nullptr, nullptr, 0, nullptr, nullptr) != 1)
    return failure(what, "cannot be encoded");
  return contents(*out);
}

Result<std::string> smime(const std::string& text, X509& signer, EVP_PKEY& key, const std::string& what) {
  constexpr int kFlags = PKCS7_DETACHED | PKCS7_TEXT;
  BioPtr data(BIO_new_mem_buf(text.data(), static_cast<int>(text.size())));
  PKCS7* p7 = PKCS7_sign(&signer, &key, nullptr, data.get(), kFlags);
  if (p7 == nullptr) return failure(what, "cannot be signed");
  BioPtr again(BIO_new_mem_buf(text.data(), static_cast<int>(text.size())));  // PKCS7_sign read the first
  BioPtr out(BIO_new(BIO_s_mem()));
  const bool ok = out && SMIME_write_PKCS7(out.get(), p7, again.get(), kFlags) == 1;
  PKCS7_free(p7);
  if (!ok) return failure(what, "cannot be encoded");
  return contents(*out);
}

}  // namespace rbsim::node::ssl
