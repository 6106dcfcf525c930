#include "auth/revocation_list.h"

#include <sys/stat.h>

#include <cerrno>
#include <string>

#include "auth/private_file.h"

namespace snapthread::auth {
namespace {

constexpr const char* kFix = "one entry a line: 'device NAME', 'operator NAME' or 'key_id HEX16' "
                             "('#' starts a comment)";

[[noreturn]] void Fail(const std::string& source, int line, const std::string& problem) {
  throw RevocationListError("revocation list " + source + " line " + std::to_string(line) + ": " +
                            problem + ". Fix: " + kFix);
}

PrivateFileNaming ListNaming(const std::string& path) {
  return {
      .path = path,
      .named = "revocation list " + path,
      .thing = "revocation list",
      .flag = "--revocations",
      .default_name = "revoked",
      .point_at = "point --revocations at a text file of revoked devices, operators and key ids",
      .make_command = "install -m 600 /dev/null",
      .missing_message = "no revocation list at " + path +
                             ". Fix: create it (install -m 600 /dev/null " + ShellQuoted(path) +
                             ") or leave the option out",
  };
}

// A name looked up without building a std::string (IsRevoked allocates nothing): compared
// with the set's (role, name) pairs through std::less<>.
struct NameKey {
  Role role;
  std::string_view name;
};
bool operator<(const std::pair<Role, std::string>& a, const NameKey& b) {
  return a.first != b.role ? a.first < b.role : std::string_view(a.second) < b.name;
}
bool operator<(const NameKey& a, const std::pair<Role, std::string>& b) {
  return a.role != b.first ? a.role < b.first : a.name < std::string_view(b.second);
}

// The whole text of the list under the private file rules.
std::string ReadListText(const PrivateFileNaming& file) {
  std::string text;
  try {
    const OpenedPrivateFile opened = OpenPrivateFile(file);
    if (opened.size > static_cast<off_t>(kMaxRevocationListBytes)) {
      throw RevocationListError(file.named + " holds " + std::to_string(opened.size) +
                                " bytes, more than " + std::to_string(kMaxRevocationListBytes) +
                                ". Fix: " + kFix);
    }
    text.resize(static_cast<std::size_t>(opened.size));
    ReadExactly(opened, file, reinterpret_cast<uint8_t*>(text.data()), text.size());
  } catch (const PrivateFileError& e) {
    throw RevocationListError(e.what());
  }
  return text;
}

}  // namespace

RevocationList RevocationList::Parse(std::string_view text, const std::string& source) {
  RevocationList list;
  int number = 0;
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    std::string_view line = text.substr(0, end);
    text = end == std::string_view::npos ? std::string_view() : text.substr(end + 1);
    ++number;
    if (!line.empty() && line.back() == '\r') Fail(source, number, "the line ends with a carriage return (CRLF)");
    if (line.empty() || line.front() == '#') continue;
    const std::size_t space = line.find(' ');
    const std::string_view word = line.substr(0, space);
    const std::string_view value = space == std::string_view::npos ? std::string_view() : line.substr(space + 1);
    if (value.empty() || value.find(' ') != std::string_view::npos) {
      Fail(source, number, "expected a word and one value separated by one space");
    }
    if (word == "key_id") {
      const std::optional<KeyId> id = KeyIdFromHex(value);
      if (!id) Fail(source, number, "a key id is 16 hex digits");
      list.key_ids_.insert(*id);
      continue;
    }
    const std::optional<Role> role = RoleFromString(word);
    if (!role || !RoleIsNamed(*role)) {
      Fail(source, number, "unknown word (revocable: device, operator, key_id)");
    }
    if (!IsValidRoleName(value)) Fail(source, number, "a name is 1 to 32 of A-Z a-z 0-9 _ -");
    list.names_.emplace(*role, std::string(value));
  }
  return list;
}

RevocationList RevocationList::Load(const std::string& path) {
  const std::string text = ReadListText(ListNaming(path));
  return Parse(text, path);
}

RevocationList RevocationList::Append(const std::string& path, std::string_view lines) {
  if (lines.empty() || lines.back() != '\n') {
    throw RevocationListError("entries appended to " + path + " must be whole lines ending in a newline");
  }
  Parse(lines, "(new entries for " + path + ")");
  const PrivateFileNaming file = ListNaming(path);
  std::string text;
  struct stat st {};
  if (lstat(path.c_str(), &st) == 0 || errno != ENOENT) {
    text = ReadListText(file);  // refused as Load refuses it
    Parse(text, path);
    if (!text.empty() && text.back() != '\n') text += '\n';
  }
  text.append(lines);
  try {
    const bool written =
        WritePrivateFile(file, reinterpret_cast<const uint8_t*>(text.data()), text.size(), true);
    (void)written;  // always, with overwrite
  } catch (const PrivateFileError& e) {
    throw RevocationListError(e.what());
  }
  return Load(path);
}

bool RevocationList::IsRevoked(Role role, std::string_view name, const KeyId& key_id) const noexcept {
  if (key_ids_.count(key_id) != 0) return true;
  return RoleIsNamed(role) && names_.find(NameKey{role, name}) != names_.end();
}

}  // namespace snapthread::auth
