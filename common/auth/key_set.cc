#include "auth/key_set.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <ctime>
#include <string>
#include <utility>

#include "auth/credential_file.h"
#include "auth/key_file.h"
#include "auth/role_keys.h"

namespace snapthread::auth {

namespace {

constexpr std::string_view kCredentialMagic = "snapthread-credential ";

int64_t NowUnixSeconds() { return static_cast<int64_t>(std::time(nullptr)); }

std::string Article(Role role) { return role == Role::kObserver || role == Role::kOperator ? "an" : "a"; }

}  // namespace

KeySet KeySet::FromRoot(SessionKey root) {
  KeySet k;
  k.role_ = Role::kServer;
  k.server_signer_.emplace(DeriveServerSigner(root));
  k.server_public_key_ = k.server_signer_->public_key();
  k.read_key_.emplace(DeriveReadKey(root));
  k.root_.emplace(std::move(root));
  k.BuildTaggers();
  return k;
}

KeySet KeySet::FromCredential(Credential credential) {
  KeySet k;
  k.role_ = credential.role;
  k.server_public_key_ = credential.server_public_key;
  if (!credential.read_key) throw CredentialError("a credential without its read key");
  k.read_key_.emplace(SessionKey::FromBytes(credential.read_key->data(), SessionKey::kBytes));
  k.credential_.emplace(std::move(credential));
  if (k.role_ == Role::kDevice) {
    if (!k.credential_->secret) throw CredentialError("a device credential without its secret");
    k.device_signer_.emplace(DeriveDeviceSigner(*k.credential_->secret));
    if (k.credential_->certificate) k.certificate_ = *k.credential_->certificate;
  }
  k.BuildTaggers();
  return k;
}

KeySet KeySet::ForRole(const SessionKey& root, Role role, std::string_view name, int64_t expires_unix_s) {
  if (role == Role::kServer) {
    return FromRoot(SessionKey::FromBytes(root.data(), SessionKey::kBytes));
  }
  KeySet k = FromCredential(IssueCredential(root, role, name, expires_unix_s));
  k.root_.emplace(SessionKey::FromBytes(root.data(), SessionKey::kBytes));
  if (role == Role::kDevice && !k.certificate_) {
    k.certificate_ = DeviceCertificate(DeriveServerSigner(root), name, expires_unix_s,
                                       k.device_signer_->public_key());
  }
  return k;
}

KeySet::KeySet(KeySet&& other) noexcept
    : role_(other.role_),
      root_(std::move(other.root_)),
      credential_(std::move(other.credential_)),
      server_signer_(std::move(other.server_signer_)),
      device_signer_(std::move(other.device_signer_)),
      certificate_(other.certificate_),
      server_public_key_(other.server_public_key_),
      read_key_(std::move(other.read_key_)) {
  BuildTaggers();  // the taggers point into this object's members
}

KeySet& KeySet::operator=(KeySet&& other) noexcept {
  if (this != &other) {
    role_ = other.role_;
    root_ = std::move(other.root_);
    credential_ = std::move(other.credential_);
    server_signer_ = std::move(other.server_signer_);
    device_signer_ = std::move(other.device_signer_);
    certificate_ = other.certificate_;
    server_public_key_ = other.server_public_key_;
    read_key_ = std::move(other.read_key_);
    BuildTaggers();
  }
  return *this;
}

KeySet::~KeySet() = default;

void KeySet::BuildTaggers() {
  tagger_ = Tagger{};
  status_tagger_ = Tagger{};
  tagger_.role = role_;
  if (role_ == Role::kServer) {
    tagger_.signer = server_signer_ ? &*server_signer_ : nullptr;
    return;
  }
  if (!credential_) return;
  tagger_.name = credential_->name;
  if (credential_->secret) {
    tagger_.expires_unix_s = credential_->expires_unix_s;
    tagger_.key_id = credential_->key_id;
    tagger_.mac_key = &*credential_->secret;
  }
  if (device_signer_) {
    status_tagger_ = tagger_;
    status_tagger_.signer = &*device_signer_;
  }
}

Tagger KeySet::ForceModelTagger() const {
  Tagger t;
  t.role = Role::kServer;
  if (role_ != Role::kDevice || mac_key() == nullptr) return t;
  t.name = credential_->name;
  t.expires_unix_s = credential_->expires_unix_s;
  t.key_id = credential_->key_id;
  t.mac_key = mac_key();
  return t;
}

bool LooksLikeCredential(const std::string& path) {
  // Never blocks (a FIFO, a device): only a regular file is read here; anything else is
  // left to the loaders, which refuse it naming the file.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return false;
  struct stat info {};
  char head[kCredentialMagic.size()];
  bool credential = false;
  if (::fstat(fd, &info) == 0 && S_ISREG(info.st_mode)) {
    credential = ::read(fd, head, sizeof head) == static_cast<ssize_t>(sizeof head) &&
                 std::string_view(head, sizeof head) == kCredentialMagic;
  }
  ::close(fd);
  return credential;
}

KeySet LoadKeySet(const std::string& path, Role needed, std::string_view program) {
  return LoadKeySet(KeyLocation{path, "--key"}, needed, program);
}

KeySet LoadKeySet(const KeyLocation& where, Role needed, std::string_view program) {
  const std::string& path = where.path;
  if (!LooksLikeCredential(path)) return KeySet::FromRoot(LoadKey(where));
  const std::string role_word(RoleToString(needed));
  if (needed == Role::kServer) {
    const Credential c = LoadCredential(path);
    throw CredentialError(std::string(program) + " needs the root key (the server host's key file); " + path +
                          " is " + Article(c.role) + " " + std::string(RoleToString(c.role)) +
                          " credential. Fix: --key the root key file made by snapthread-keygen on this host");
  }
  Credential c = LoadCredential(path);
  RequireRole(c, needed, program, path);
  if (c.ExpiredAt(NowUnixSeconds())) {
    throw CredentialError(std::string(program) + ": the " + role_word + " credential " + path + " expired at " +
                          std::to_string(c.expires_unix_s) +
                          " (Unix seconds). Fix: issue a new one on the server host (snapthread-keygen --role " +
                          role_word + ")");
  }
  return KeySet::FromCredential(std::move(c));
}

}  // namespace snapthread::auth
