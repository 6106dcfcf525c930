#include "auth/credential_file.h"

#include <sodium.h>

#include <string>
#include <vector>

#include "auth/private_file.h"

namespace snapthread::auth {
namespace {

PrivateFileNaming CredentialNaming(const std::string& path) {
  return {
      .path = path,
      .named = "credential " + path,
      .thing = "credential",
      .flag = "--credential",
      .default_name = "snapthread.cred",
      .point_at = "point --credential at the credential file issued by snapthread-keygen --role",
      .make_command = "snapthread-keygen --role ROLE --credential",
      .missing_message = "no credential at " + path +
                             ". Fix: issue one on the server host (snapthread-keygen --role ROLE "
                             "--credential FILE) and copy it here with scp -p",
  };
}

// Wipes a buffer that held a credential's text (its secrets) on every way out.
struct WipedBytes {
  std::vector<uint8_t> bytes;
  ~WipedBytes() {
    if (!bytes.empty()) sodium_memzero(bytes.data(), bytes.size());
  }
};

}  // namespace

void WriteCredentialFile(const std::string& path, const Credential& credential, bool overwrite) {
  const PrivateFileNaming file = CredentialNaming(path);
  std::string text = FormatCredential(credential);
  bool written = false;
  try {
    written = WritePrivateFile(file, reinterpret_cast<const uint8_t*>(text.data()), text.size(), overwrite);
  } catch (const PrivateFileError& e) {
    sodium_memzero(text.data(), text.size());
    throw CredentialError(e.what());
  }
  sodium_memzero(text.data(), text.size());
  if (!written) {
    throw CredentialError("refusing to overwrite the existing " + file.named +
                          ". Fix: remove it first, or choose another file");
  }
}

Credential LoadCredential(const std::string& path) {
  const PrivateFileNaming file = CredentialNaming(path);
  WipedBytes text;
  try {
    const OpenedPrivateFile opened = OpenPrivateFile(file);
    if (opened.size > static_cast<off_t>(kMaxCredentialFileBytes)) {
      throw CredentialError(file.named + " holds " + std::to_string(opened.size) +
                            " bytes; a credential is at most " + std::to_string(kMaxCredentialFileBytes) +
                            ". Fix: pass the credential file issued by snapthread-keygen --role");
    }
    text.bytes.resize(static_cast<std::size_t>(opened.size));
    ReadExactly(opened, file, text.bytes.data(), text.bytes.size());
  } catch (const PrivateFileError& e) {
    throw CredentialError(e.what());
  }
  return ParseCredential(
      std::string_view(reinterpret_cast<const char*>(text.bytes.data()), text.bytes.size()), path);
}

}  // namespace snapthread::auth
