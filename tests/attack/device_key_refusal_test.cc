// The session key file as an attacker with a local account would plant it, against the
// real binaries that take a key (server, device, viewer, web, scene-shape, ctl): a missing
// file (a typo must not make a new key), a symbolic link, a file owned by another user, a
// directory others may write, a key others may read. Each binary must refuse to start,
// exit non-zero within seconds, and name the file and the fix; nothing is created.
// Also: only snapthread-server --create-key makes a missing key, and not in such a
// directory; and every binary given a credential of a role it does not play refuses to
// start, naming the role it needs.
#include <gtest/gtest.h>

#include <pwd.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "test_support.h"

namespace snapthread {
namespace {

namespace fs = std::filesystem;
using test_support::BinDir;
using test_support::ScopedTempDir;
using test_support::SourceDir;

struct Binary {
  std::string name;
  std::vector<std::string> args;  // everything but the key
};

std::vector<Binary> KeyTakers() {
  const std::string scene = SourceDir() + "/scenes/zeeman.yaml";
  const std::string url = test_support::kLoopbackLcmUrl;
  const std::string session = test_support::UniqueSession("KEYREF");
  return {
      {"snapthread-server",
       {"--scene", scene, "--session", session, "--lcm-url", url, "--duration", "3"}},
      {"snapthread-device",
       {"--backend", "sim-path", "--scene", scene, "--session", session, "--lcm-url", url,
        "--duration", "1", "--no-rt"}},
      {"snapthread-viewer",
       {"--grasp-mode", "--scene", scene, "--session", session, "--lcm-url", url}},
      {"snapthread-web",
       {"--session", session, "--lcm-url", url, "--port", "0", "--duration-s", "3"}},
      {"snapthread-scene-shape",
       {"--scene", scene, "--steps", "2", "--session", session, "--lcm-url", url, "--duration",
        "1"}},
      {"snapthread-ctl", {"--session", session, "--lcm-url", url, "--timeout-s", "1", "status"}},
  };
}

// The key takers by the role each plays, and the words its refusal of another role's
// credential must contain.
struct RolePlayer {
  std::string binary;
  std::vector<std::string> refused_roles;  // credentials it must refuse
  std::string needs;                       // named in the refusal
};
std::vector<RolePlayer> RolePlayers() {
  return {
      {"snapthread-server", {"observer", "device", "operator"}, "root key"},
      {"snapthread-device", {"observer", "operator"}, "device"},
      {"snapthread-viewer", {"device", "operator"}, "observer"},
      {"snapthread-web", {"device", "operator"}, "observer"},
      {"snapthread-ctl", {"observer", "device"}, "operator"},
  };
}

// A valid key (32 bytes, 0600) at path.
void WriteKey(const std::string& path, mode_t mode = 0600) {
  std::ofstream(path, std::ios::binary) << std::string(32, 'k');
  ASSERT_EQ(chmod(path.c_str(), mode), 0) << path;
}

struct Outcome {
  bool exited = false;
  int code = -1;
  std::string output;
};

Outcome RunBinary(const std::vector<std::string>& argv, const std::string& log) {
  test_support::ChildProcess child(argv, test_support::OneLog(log, true));
  Outcome o;
  o.exited = child.started() && child.WaitOrKill(20.0 * test_support::SpeedScale(), &o.code, 0.2);
  o.output = child.Out();
  return o;
}

// One way of planting the key: makes it under `dir`, returns the path to pass, and what
// the refusal must say.
struct Plant {
  std::string name;
  std::function<std::string(const std::string& dir)> make;
  std::function<std::vector<std::string>(const std::string& path)> expect;
  bool needs_root = false;
};

std::vector<Plant> Plants() {
  return {
      {"missing",
       [](const std::string& dir) { return dir + "/sesion.key"; },
       [](const std::string& p) {
         return std::vector<std::string>{"no session key at " + p, "snapthread-keygen --key " + p};
       }},
      {"symlink",
       [](const std::string& dir) {
         WriteKey(dir + "/real.key");
         const std::string link = dir + "/session.key";
         EXPECT_EQ(symlink((dir + "/real.key").c_str(), link.c_str()), 0);
         return link;
       },
       [](const std::string& p) {
         return std::vector<std::string>{p, "symbolic link", "use the real path"};
       }},
      {"foreign-owned",
       [](const std::string& dir) {
         const std::string p = dir + "/session.key";
         WriteKey(p);
         const passwd* nobody = getpwnam("nobody");
         EXPECT_NE(nobody, nullptr);
         if (nobody != nullptr) {
           EXPECT_EQ(chown(p.c_str(), nobody->pw_uid, nobody->pw_gid), 0);
         }
         return p;
       },
       [](const std::string& p) {
         return std::vector<std::string>{p, "owned by nobody", "chown "};
       },
       true},
      {"writable-parent",
       [](const std::string& dir) {
         const std::string shared = dir + "/shared";
         fs::create_directory(shared);
         EXPECT_EQ(chmod(shared.c_str(), 0777), 0);
         WriteKey(shared + "/session.key");
         return shared + "/session.key";
       },
       [](const std::string& p) {
         return std::vector<std::string>{p, "chmod go-w " + fs::path(p).parent_path().string()};
       }},
      {"group-readable",
       [](const std::string& dir) {
         WriteKey(dir + "/session.key", 0640);
         return dir + "/session.key";
       },
       [](const std::string& p) { return std::vector<std::string>{p, "0640", "chmod 0600 " + p}; }},
  };
}

TEST(KeyRefusalAttackTest, EveryBinaryRefusesAPlantedKeyNamingTheFix) {
  const ScopedTempDir root("key_refusal");
  const bool root_user = geteuid() == 0;
  int refused = 0;
  for (const Plant& plant : Plants()) {
    if (plant.needs_root && !root_user) {
      ADD_FAILURE() << plant.name << ": needs root to chown a key to nobody (run as root)";
      continue;
    }
    for (const Binary& b : KeyTakers()) {
      const std::string dir = root.path() + "/" + plant.name + "-" + b.name;
      fs::create_directory(dir);
      const std::string key = plant.make(dir);
      std::vector<std::string> argv = {BinDir() + "/" + b.name};
      argv.insert(argv.end(), b.args.begin(), b.args.end());
      argv.push_back("--key");
      argv.push_back(key);
      const Outcome o = RunBinary(argv, dir + "/output.txt");
      const std::string what = plant.name + " key, " + b.name;
      ASSERT_TRUE(o.exited) << what << ": did not exit within 20 s\n" << o.output;
      EXPECT_NE(o.code, 0) << what << " started anyway\n" << o.output;
      for (const std::string& s : plant.expect(key)) {
        EXPECT_NE(o.output.find(s), std::string::npos)
            << what << ": the message does not say \"" << s << "\"\n" << o.output;
      }
      if (plant.name == "missing") {
        EXPECT_FALSE(fs::exists(key)) << what << " created the key";
      }
      ++refused;
    }
  }
  EXPECT_EQ(refused, static_cast<int>(Plants().size() * KeyTakers().size()));
}

// A credential of a role the binary does not play: it refuses to start within seconds,
// naming the program and the role it needs; nothing listens or publishes.
TEST(KeyRefusalAttackTest, EveryBinaryRefusesACredentialOfARoleItDoesNotPlay) {
  const ScopedTempDir root("key_roles");
  const std::string root_key = root.path() + "/root.key";
  Outcome o = RunBinary({BinDir() + "/snapthread-keygen", "--key", root_key}, root.path() + "/keygen.txt");
  ASSERT_EQ(o.code, 0) << o.output;
  for (const std::string role : {"observer", "device", "operator"}) {
    std::vector<std::string> argv = {BinDir() + "/snapthread-keygen", "--key", root_key, "--role", role,
                                     "--out", root.path() + "/" + role + ".cred"};
    if (role == "device") argv.insert(argv.end(), {"--device", "hand"});
    o = RunBinary(argv, root.path() + "/keygen_" + role + ".txt");
    ASSERT_EQ(o.code, 0) << role << "\n" << o.output;
  }
  std::map<std::string, std::vector<std::string>> args;
  for (const Binary& b : KeyTakers()) args[b.name] = b.args;
  // The viewer observes; with --grasp-mode it would drive a grasp as a device.
  std::erase(args["snapthread-viewer"], std::string("--grasp-mode"));
  int refused = 0;
  for (const RolePlayer& p : RolePlayers()) {
    if (!fs::exists(BinDir() + "/" + p.binary)) continue;  // a build without the GUI or web
    for (const std::string& role : p.refused_roles) {
      std::vector<std::string> argv = {BinDir() + "/" + p.binary};
      argv.insert(argv.end(), args[p.binary].begin(), args[p.binary].end());
      argv.insert(argv.end(), {"--key", root.path() + "/" + role + ".cred"});
      o = RunBinary(argv, root.path() + "/" + p.binary + "_" + role + ".txt");
      const std::string what = p.binary + " given the " + role + " credential";
      if (!o.exited) {
        ADD_FAILURE() << what << ": started (did not exit within 20 s)\n" << o.output;
        continue;
      }
      EXPECT_NE(o.code, 0) << what << " started anyway\n" << o.output;
      EXPECT_NE(o.output.find(p.needs), std::string::npos) << what << ": does not name \"" << p.needs << "\"\n"
                                                           << o.output;
      EXPECT_NE(o.output.find(p.binary), std::string::npos) << what << "\n" << o.output;
      ++refused;
    }
  }
  EXPECT_GE(refused, 7);  // server, device and ctl at least
}

// SNAPTHREAD_KEY_FILE naming a missing file is refused the same way, and names the variable.
TEST(KeyRefusalAttackTest, MissingKeyFromTheEnvironmentIsRefused) {
  const ScopedTempDir root("key_refusal_env");
  const std::string key = root.path() + "/typo.key";
  const char* previous = std::getenv("SNAPTHREAD_KEY_FILE");
  const std::string saved = previous != nullptr ? previous : "";
  ::setenv("SNAPTHREAD_KEY_FILE", key.c_str(), 1);
  for (const Binary& b : KeyTakers()) {
    std::vector<std::string> argv = {BinDir() + "/" + b.name};
    argv.insert(argv.end(), b.args.begin(), b.args.end());
    const Outcome o = RunBinary(argv, root.path() + "/" + b.name + ".txt");
    ASSERT_TRUE(o.exited) << b.name << "\n" << o.output;
    EXPECT_NE(o.code, 0) << b.name << "\n" << o.output;
    EXPECT_NE(o.output.find("no session key at " + key + " (SNAPTHREAD_KEY_FILE)"), std::string::npos)
        << b.name << "\n" << o.output;
    EXPECT_FALSE(fs::exists(key)) << b.name;
  }
  if (previous != nullptr) {
    ::setenv("SNAPTHREAD_KEY_FILE", saved.c_str(), 1);
  } else {
    ::unsetenv("SNAPTHREAD_KEY_FILE");
  }
}

// The one way a server makes a key: --create-key, mode 0600, and never into a directory
// others may write.
TEST(KeyRefusalAttackTest, OnlyCreateKeyMakesAKeyAndNotInAWritableDirectory) {
  const ScopedTempDir root("key_create");
  const std::string scene = SourceDir() + "/scenes/zeeman.yaml";
  const std::string key = root.path() + "/made/session.key";
  const std::vector<std::string> server = {BinDir() + "/snapthread-server", "--scene", scene,
                                           "--session", test_support::UniqueSession("KEYMK"),
                                           "--lcm-url", test_support::kLoopbackLcmUrl,
                                           "--duration", "0.5", "--key", key};
  std::vector<std::string> argv = server;
  argv.push_back("--create-key");
  Outcome o = RunBinary(argv, root.path() + "/create.txt");
  ASSERT_TRUE(o.exited) << o.output;
  EXPECT_EQ(o.code, 0) << o.output;
  ASSERT_TRUE(fs::exists(key)) << o.output;
  struct stat st {};
  ASSERT_EQ(stat(key.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0600u);
  EXPECT_EQ(st.st_size, 32);
  // "created a new session key FILE" before the roles, "created a new root key FILE" with them.
  EXPECT_TRUE(o.output.find("created a new session key " + key) != std::string::npos ||
              o.output.find("created a new root key " + key) != std::string::npos)
      << o.output;
  // The same server without --create-key now loads it.
  o = RunBinary(server, root.path() + "/load.txt");
  EXPECT_EQ(o.code, 0) << o.output;

  const std::string shared = root.path() + "/shared";
  fs::create_directory(shared);
  ASSERT_EQ(chmod(shared.c_str(), 0777), 0);
  argv = server;
  argv[argv.size() - 1] = shared + "/session.key";
  argv.push_back("--create-key");
  o = RunBinary(argv, root.path() + "/shared.txt");
  ASSERT_TRUE(o.exited) << o.output;
  EXPECT_NE(o.code, 0) << o.output;
  EXPECT_NE(o.output.find("chmod go-w " + shared), std::string::npos) << o.output;
  EXPECT_FALSE(fs::exists(shared + "/session.key"));
}

}  // namespace
}  // namespace snapthread
