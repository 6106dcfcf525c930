#include "auth/credential.h"

#include <sodium.h>

#include <array>
#include <charconv>
#include <string>

#include "auth/device_certificate.h"
#include "auth/role_keys.h"

namespace snapthread::auth {
namespace {

enum Field {
  kRole, kName, kExpires, kRootId, kKeyId, kServerPublicKey, kReadKey, kSecret, kCertificate, kFieldCount
};
constexpr std::array<std::string_view, kFieldCount> kFieldNames = {
    "role", "name", "expires", "root_id", "key_id", "server_public_key", "read_key", "secret", "certificate"};

constexpr std::string_view kHeader = "snapthread-credential ";
// More than the longest text FormatCredential makes (about 400 bytes).
constexpr std::size_t kMaxFormattedBytes = 1024;
constexpr const char* kReissue =
    "issue a new credential on the server host (snapthread-keygen --role ...) and copy it "
    "here with scp -p; a credential is never edited by hand";

struct Line {
  std::string_view value;
  int number = 0;  // 0: absent
};

class Parser {
 public:
  Parser(std::string_view text, const std::string& source) : text_(text), source_(source) {}
  Credential Parse();

 private:
  [[noreturn]] void Fail(int line, const std::string& problem, const std::string& fix = kReissue) const {
    throw CredentialError("credential " + source_ + (line > 0 ? " line " + std::to_string(line) : "") +
                          ": " + problem + ". Fix: " + fix);
  }
  void SplitLines();
  void TakeLine(std::string_view line, int number);
  Role ParseRole() const;
  void CheckFieldsOfRole(Role role) const;
  int64_t ParseExpiry() const;
  void ParseBytes(Field field, uint8_t* out, std::size_t size) const;
  SessionKey ParseKey(Field field) const;
  void CheckCertificate(Credential* c) const;

  std::string_view text_;
  const std::string& source_;
  std::array<Line, kFieldCount> fields_{};
};

void Parser::SplitLines() {
  std::string_view rest = text_;
  int number = 0;
  while (!rest.empty()) {
    const std::size_t end = rest.find('\n');
    const std::string_view line = rest.substr(0, end);
    rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 1);
    ++number;
    if (number == 1) {
      if (line.substr(0, kHeader.size()) != kHeader) {
        Fail(1, "it does not start with 'snapthread-credential " +
                    std::to_string(kCredentialFormatVersion) + "' (not a credential file?)",
             "pass the credential file issued for this role (--credential FILE)");
      }
      if (line.substr(kHeader.size()) != std::to_string(kCredentialFormatVersion)) {
        Fail(1, "format version '" + std::string(line.substr(kHeader.size(), 8)) +
                    "' is not the version this build reads (" +
                    std::to_string(kCredentialFormatVersion) + ")",
             "issue the credential with the snapthread-keygen of this build");
      }
      continue;
    }
    TakeLine(line, number);
  }
  if (number == 0) Fail(0, "the file is empty", kReissue);
}

void Parser::TakeLine(std::string_view line, int number) {
  if (line.empty()) Fail(number, "an empty line");
  if (line.back() == '\r') Fail(number, "the line ends with a carriage return (CRLF)");
  const std::size_t space = line.find(' ');
  if (space == std::string_view::npos) Fail(number, "no value (a line is 'word value')");
  const std::string_view word = line.substr(0, space);
  const std::string_view value = line.substr(space + 1);
  int field = -1;
  for (int f = 0; f < kFieldCount; ++f) {
    if (word == kFieldNames[f]) field = f;
  }
  if (field < 0) {
    bool printable = word.size() <= 32;
    for (const char c : word) printable = printable && ((c >= 'a' && c <= 'z') || c == '_');
    Fail(number, printable ? "unknown line '" + std::string(word) + "'" : "an unknown line");
  }
  if (value.empty() || value.find(' ') != std::string_view::npos) {
    Fail(number, "'" + std::string(word) + "' needs exactly one value after one space");
  }
  Line& slot = fields_[static_cast<std::size_t>(field)];
  if (slot.number != 0) {
    Fail(number, "a second '" + std::string(word) + "' line (the first is line " +
                     std::to_string(slot.number) + ")");
  }
  slot = {value, number};
}

Role Parser::ParseRole() const {
  const Line& line = fields_[kRole];
  if (line.number == 0) Fail(0, "no 'role' line");
  const std::optional<Role> role = RoleFromString(line.value);
  if (!role) Fail(line.number, "the role must be device, operator or observer");
  if (*role == Role::kServer) {
    Fail(line.number, "a server takes no credential",
         "the server uses the root key file itself (--key)");
  }
  return *role;
}

void Parser::CheckFieldsOfRole(Role role) const {
  const std::string role_word(RoleToString(role));
  for (int f = 0; f < kFieldCount; ++f) {
    const bool only_named = f == kName || f == kSecret;
    const bool wanted = f == kCertificate ? role == Role::kDevice : !only_named || RoleIsNamed(role);
    const Line& line = fields_[static_cast<std::size_t>(f)];
    const std::string word(kFieldNames[static_cast<std::size_t>(f)]);
    if (wanted && line.number == 0) Fail(0, "no '" + word + "' line (a " + role_word + " credential needs one)");
    if (!wanted && line.number != 0) {
      Fail(line.number, "an " + role_word + " credential has no '" + word + "' line");
    }
  }
}

int64_t Parser::ParseExpiry() const {
  const Line& line = fields_[kExpires];
  if (line.value == "never") return kNeverExpires;
  int64_t value = 0;
  const char* begin = line.value.data();
  const char* end = begin + line.value.size();
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  if (ec != std::errc() || ptr != end || value <= 0 || line.value.front() == '0') {
    Fail(line.number, "'expires' is 'never' or a positive number of Unix seconds");
  }
  return value;
}

void Parser::ParseBytes(Field field, uint8_t* out, std::size_t size) const {
  const Line& line = fields_[field];
  if (!FromHex(line.value, out, size)) {
    Fail(line.number, "'" + std::string(kFieldNames[field]) + "' must be " + std::to_string(2 * size) +
                          " hex digits (" + std::to_string(line.value.size()) + " characters given" +
                          (line.value.size() == 2 * size ? ", not all hex" : "") + ")");
  }
}

SessionKey Parser::ParseKey(Field field) const {
  uint8_t bytes[SessionKey::kBytes];
  ParseBytes(field, bytes, sizeof bytes);
  SessionKey key = SessionKey::FromBytes(bytes, sizeof bytes);
  sodium_memzero(bytes, sizeof bytes);
  return key;
}

// A device's certificate must be the server's (server_public_key) for this name, expiry
// and the signing key of this secret: an edited name or expiry, or a credential pieced
// together from two roots, shows here.
void Parser::CheckCertificate(Credential* c) const {
  DeviceCertificateBytes certificate{};
  ParseBytes(kCertificate, certificate.data(), certificate.size());
  const PublicKey device_public_key = DeriveDeviceSigner(*c->secret).public_key();
  if (!VerifyDeviceCertificate(c->server_public_key, c->name, c->expires_unix_s, device_public_key,
                               certificate.data())) {
    Fail(fields_[kCertificate].number,
         "'certificate' does not verify with server_public_key for this name, expiry and secret "
         "(edited, or issued from another root key)");
  }
  c->certificate = certificate;
}

Credential Parser::Parse() {
  SplitLines();
  Credential c;
  c.role = ParseRole();
  CheckFieldsOfRole(c.role);
  if (RoleIsNamed(c.role)) {
    c.name = std::string(fields_[kName].value);
    if (!IsValidRoleName(c.name)) {
      Fail(fields_[kName].number, "the name must be 1 to 32 of A-Z a-z 0-9 _ -");
    }
  }
  c.expires_unix_s = ParseExpiry();
  ParseBytes(kRootId, c.root_id.data(), c.root_id.size());
  ParseBytes(kKeyId, c.key_id.data(), c.key_id.size());
  ParseBytes(kServerPublicKey, c.server_public_key.data(), c.server_public_key.size());
  c.read_key.emplace(ParseKey(kReadKey));
  if (RoleIsNamed(c.role)) c.secret.emplace(ParseKey(kSecret));
  // The id is a function of the key: a damaged or edited key (or id) shows here.
  const SessionKey& identified = RoleIsNamed(c.role) ? *c.secret : *c.read_key;
  if (SecretKeyId(KeyIdLabel(c.role), identified) != c.key_id) {
    Fail(fields_[kKeyId].number, "'key_id' does not match the key of this credential");
  }
  if (c.role == Role::kDevice) CheckCertificate(&c);
  return c;
}

std::string ExpiryText(int64_t expires_unix_s) {
  return expires_unix_s == kNeverExpires ? "never" : std::to_string(expires_unix_s);
}

}  // namespace

Credential IssueCredential(const SessionKey& root, Role role, std::string_view name,
                           int64_t expires_unix_s) {
  if (role == Role::kServer) {
    throw CredentialError("no credential is issued for the server: it holds the root key file itself");
  }
  if (RoleIsNamed(role) && !IsValidRoleName(name)) {
    throw CredentialError("'" + std::string(name) + "' is not a valid " + std::string(RoleToString(role)) +
                          " name. Fix: 1 to 32 of A-Z a-z 0-9 _ -");
  }
  if (!RoleIsNamed(role) && !name.empty()) {
    throw CredentialError("an observer credential has no name. Fix: leave the name out");
  }
  if (expires_unix_s < 0) {
    throw CredentialError("a negative expiry. Fix: Unix seconds in the future, or 0 for never");
  }
  Credential c;
  c.role = role;
  c.name = std::string(name);
  c.expires_unix_s = expires_unix_s;
  c.root_id = RootKeyId(root);
  c.server_public_key = DeriveServerPublicKey(root);
  c.read_key.emplace(DeriveReadKey(root));
  if (RoleIsNamed(role)) {
    c.secret.emplace(DeriveRoleKey(root, role, name, expires_unix_s));
    c.key_id = SecretKeyId(KeyIdLabel(role), *c.secret);
    if (role == Role::kDevice) {
      c.certificate = DeviceCertificate(DeriveServerSigner(root), name, expires_unix_s,
                                        DeriveDeviceSigner(*c.secret).public_key());
    }
  } else {
    c.key_id = SecretKeyId(KeyIdLabel(role), *c.read_key);
  }
  return c;
}

std::string FormatCredential(const Credential& c) {
  // Reserved once and hex written in place: no reallocation or temporary leaves a copy of
  // a secret in freed memory (the caller wipes `text`).
  std::string text;
  text.reserve(kMaxFormattedBytes);
  auto line = [&](std::string_view word, std::string_view value) {
    text.append(word).append(" ").append(value).append("\n");
  };
  auto hex_line = [&](std::string_view word, const uint8_t* bytes, std::size_t size) {
    text.append(word).append(" ");
    const std::size_t at = text.size();
    text.resize(at + 2 * size + 1);
    sodium_bin2hex(text.data() + at, 2 * size + 1, bytes, size);
    text.back() = '\n';
  };
  text.append(kHeader).append(std::to_string(kCredentialFormatVersion)).append("\n");
  line("role", RoleToString(c.role));
  if (RoleIsNamed(c.role)) line("name", c.name);
  line("expires", ExpiryText(c.expires_unix_s));
  hex_line("root_id", c.root_id.data(), c.root_id.size());
  hex_line("key_id", c.key_id.data(), c.key_id.size());
  hex_line("server_public_key", c.server_public_key.data(), c.server_public_key.size());
  if (c.read_key) hex_line("read_key", c.read_key->data(), SessionKey::kBytes);
  if (c.secret) hex_line("secret", c.secret->data(), SessionKey::kBytes);
  if (c.certificate) hex_line("certificate", c.certificate->data(), c.certificate->size());
  return text;
}

Credential ParseCredential(std::string_view text, const std::string& source) {
  InitSodium();
  return Parser(text, source).Parse();
}

void RequireRole(const Credential& credential, Role needed, std::string_view user,
                 const std::string& source) {
  if (credential.role == needed) return;
  const std::string want(RoleToString(needed));
  const std::string have(RoleToString(credential.role));
  throw CredentialError(std::string(user) + " needs " + (needed == Role::kOperator || needed == Role::kObserver ? "an " : "a ") +
                        want + " credential; " + source + " is " +
                        (credential.role == Role::kOperator || credential.role == Role::kObserver ? "an " : "a ") +
                        have + " credential" +
                        (credential.name.empty() ? "" : " (" + credential.name + ")") +
                        ". Fix: pass the " + want + " credential issued for this host "
                        "(snapthread-keygen --role " + want + " on the server host)");
}

}  // namespace snapthread::auth
