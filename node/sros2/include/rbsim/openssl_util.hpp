// The OpenSSL pieces of DDS Security (node/dds/src/security.cpp, node/sros2/src/keystore.cpp): owned handles,
// reading and checking PEM certificates, keys and S/MIME documents, and making them. Errors name the file.
#pragma once

#include <openssl/evp.h>
#include <openssl/x509.h>

#include <memory>
#include <string>

#include "rbsim/status.hpp"

namespace rbsim::node::ssl {

struct X509Free {
  void operator()(X509* x) const { X509_free(x); }
};
struct KeyFree {
  void operator()(EVP_PKEY* k) const { EVP_PKEY_free(k); }
};
using X509Ptr = std::unique_ptr<X509, X509Free>;
using KeyPtr = std::unique_ptr<EVP_PKEY, KeyFree>;

// OpenSSL's last error as text ("" when none).
std::string last_error();

Result<X509Ptr> read_certificate(const std::string& path);
Result<KeyPtr> read_private_key(const std::string& path);
// `cert` is signed by `ca` (the signature only: rbsim makes both).
Status verify_issued_by(X509& cert, X509& ca);
// An S/MIME document (detached signature, text) whose signer chains to `ca`.
Status verify_smime(const std::string& path, X509& ca);

// A new EC P-256 key, as sros2 makes them.
Result<KeyPtr> generate_key();
// A certificate for `subject` (its common name), valid for 10 years: self-signed by `key` when
// `issuer` is null (a CA, BasicConstraints CA:TRUE, pathlen 1), else signed by the issuer's key.
Result<X509Ptr> make_certificate(const std::string& common_name, EVP_PKEY& subject_key, X509* issuer,
                                 EVP_PKEY& issuer_key);
// PEM text of a certificate and of a private key (unencrypted PKCS#8), and an S/MIME signed copy of
// `text` (detached, text/plain, SHA-256: what sros2's create_smime_signed_file writes). The keystore
// writes them (src/keystore.cpp, through AtomicFile); `what` names the file in an error.
Result<std::string> certificate_pem(X509& cert, const std::string& what);
Result<std::string> private_key_pem(EVP_PKEY& key, const std::string& what);
Result<std::string> smime(const std::string& text, X509& signer, EVP_PKEY& key, const std::string& what);

}  // namespace rbsim::node::ssl
