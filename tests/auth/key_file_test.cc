// The session key file: where it is looked for, what is refused (with the file and the
// fix in the message: missing, symbolic link, another owner, group/other bits, a writable
// or foreign directory), and how snapthread-keygen and the server's --create-key make it.
#include <gtest/gtest.h>
#include <pwd.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "auth/key_file.h"

namespace snapthread::auth {
namespace {

namespace fs = std::filesystem;

class KeyFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (fs::temp_directory_path() / "snapthread_key_XXXXXX").string();
    ASSERT_NE(mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Path(const std::string& name) const { return (fs::path(dir_) / name).string(); }
  static KeyLocation At(const std::string& path) { return {path, "--key"}; }

  void WriteBytes(const std::string& path, size_t n, mode_t mode) {
    std::ofstream(path, std::ios::binary) << std::string(n, 'k');
    ASSERT_EQ(chmod(path.c_str(), mode), 0);
  }

  static mode_t ModeOf(const std::string& path) {
    struct stat st {};
    EXPECT_EQ(stat(path.c_str(), &st), 0) << path;
    return st.st_mode & 07777;
  }

  // The message LoadKey throws for `path` ("" when it loads).
  static std::string LoadError(const std::string& path) {
    try {
      LoadKey(At(path));
    } catch (const KeyFileError& e) {
      return e.what();
    }
    return "";
  }

  std::string dir_;
};

// ---- where the key is looked for -----------------------------------------------------

EnvLookup FakeEnv(std::map<std::string, std::string> vars) {
  return [vars = std::move(vars)](const char* name) -> const char* {
    const auto it = vars.find(name);
    return it == vars.end() ? nullptr : it->second.c_str();
  };
}

TEST(KeyPathTest, FlagWinsOverEnvironmentAndDefault) {
  const auto env = FakeEnv({{"SNAPTHREAD_KEY_FILE", "/env/k"}, {"XDG_CONFIG_HOME", "/xdg"},
                            {"HOME", "/home/u"}});
  const KeyLocation where = ResolveKeyPath("/flag/k", env);
  EXPECT_EQ(where.path, "/flag/k");
  EXPECT_EQ(where.origin, "--key");
}

TEST(KeyPathTest, EnvironmentWinsOverXdg) {
  const auto env = FakeEnv({{"SNAPTHREAD_KEY_FILE", "/env/k"}, {"XDG_CONFIG_HOME", "/xdg"},
                            {"HOME", "/home/u"}});
  const KeyLocation where = ResolveKeyPath("", env);
  EXPECT_EQ(where.path, "/env/k");
  EXPECT_EQ(where.origin, "SNAPTHREAD_KEY_FILE");
}

TEST(KeyPathTest, XdgConfigHomeThenHome) {
  EXPECT_EQ(ResolveKeyPath("", FakeEnv({{"XDG_CONFIG_HOME", "/xdg"}, {"HOME", "/home/u"}})).path,
            "/xdg/snapthread/session.key");
  EXPECT_EQ(ResolveKeyPath("", FakeEnv({{"HOME", "/home/u"}})).path,
            "/home/u/.config/snapthread/session.key");
  // Empty values count as unset; a relative XDG_CONFIG_HOME is invalid (XDG spec).
  EXPECT_EQ(ResolveKeyPath("", FakeEnv({{"SNAPTHREAD_KEY_FILE", ""}, {"XDG_CONFIG_HOME", "rel"},
                                        {"HOME", "/home/u"}}))
                .path,
            "/home/u/.config/snapthread/session.key");
}

TEST(KeyPathTest, RealEnvironmentIsUsed) {
  ASSERT_EQ(setenv("SNAPTHREAD_KEY_FILE", "/from/the/environment", 1), 0);
  EXPECT_EQ(ResolveKeyPath("").path, "/from/the/environment");
  EXPECT_EQ(ResolveKeyPath("/flag").path, "/flag");
  unsetenv("SNAPTHREAD_KEY_FILE");
}

// ---- what is refused -----------------------------------------------------------------

TEST_F(KeyFileTest, GroupOrWorldReadableKeyIsRefusedWithTheFix) {
  const std::string path = Path("session.key");
  for (const mode_t mode : {0644, 0640, 0604, 0660, 0602, 0620}) {
    WriteBytes(path, 32, mode);
    const std::string error = LoadError(path);
    EXPECT_NE(error.find(path), std::string::npos) << error;
    EXPECT_NE(error.find("chmod 0600 " + path), std::string::npos) << error;
    char octal[8];
    std::snprintf(octal, sizeof octal, "%04o", static_cast<unsigned>(mode));
    EXPECT_NE(error.find(octal), std::string::npos) << error;
  }
}

TEST_F(KeyFileTest, OwnerOnlyKeyIsAccepted) {
  const std::string path = Path("session.key");
  for (const mode_t mode : {0600, 0400}) {
    WriteBytes(path, 32, mode);
    EXPECT_EQ(LoadError(path), "");
  }
  // Same bytes, same key: the id is a function of the key.
  EXPECT_EQ(LoadKey(At(path)).Id(), LoadKey(At(path)).Id());
  EXPECT_EQ(LoadKey(At(path)).Id().size(), 16u);
}

TEST_F(KeyFileTest, FixInTheMessageIsQuotedForTheShell) {
  const std::string path = Path("my key");
  WriteBytes(path, 32, 0644);
  EXPECT_NE(LoadError(path).find("chmod 0600 '" + path + "'"), std::string::npos) << LoadError(path);
}

TEST_F(KeyFileTest, WrongSizeIsRefused) {
  const std::string path = Path("session.key");
  for (const size_t n : {0, 16, 31, 33, 64}) {
    WriteBytes(path, n, 0600);
    const std::string error = LoadError(path);
    EXPECT_NE(error.find(path), std::string::npos) << error;
    EXPECT_NE(error.find("holds " + std::to_string(n) + " bytes"), std::string::npos) << error;
    EXPECT_NE(error.find("snapthread-keygen --force"), std::string::npos) << error;
  }
}

TEST_F(KeyFileTest, MissingFileSaysHowToMakeOne) {
  const std::string path = Path("nowhere/session.key");
  const std::string error = LoadError(path);
  EXPECT_NE(error.find(path), std::string::npos) << error;
  EXPECT_NE(error.find("snapthread-keygen"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(path));  // LoadKey never creates
}

TEST_F(KeyFileTest, MissingFileIsNeverCreatedAndTheMessageSaysHow) {
  const std::string path = Path("sesion.key");  // a typo of session.key
  const std::string error = LoadError(path);
  EXPECT_NE(error.find("no session key at " + path), std::string::npos) << error;
  EXPECT_NE(error.find("snapthread-keygen --key " + path), std::string::npos) << error;
  EXPECT_NE(error.find("--create-key"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(path));
}

TEST_F(KeyFileTest, SymbolicLinkIsRefusedNamingTheRealPath) {
  const std::string real = Path("real.key");
  WriteBytes(real, 32, 0600);
  const std::string link = Path("session.key");
  ASSERT_EQ(symlink(real.c_str(), link.c_str()), 0);
  const std::string error = LoadError(link);
  EXPECT_NE(error.find(link), std::string::npos) << error;
  EXPECT_NE(error.find("symbolic link"), std::string::npos) << error;
  EXPECT_NE(error.find("use the real path: --key " + fs::canonical(real).string()), std::string::npos)
      << error;
  // A dangling link is refused the same way, not reported missing (or created through).
  const std::string dangling = Path("dangling.key");
  ASSERT_EQ(symlink(Path("nothing").c_str(), dangling.c_str()), 0);
  EXPECT_NE(LoadError(dangling).find("symbolic link"), std::string::npos) << LoadError(dangling);
  EXPECT_NE(LoadError(dangling).find("points to " + Path("nothing")), std::string::npos)
      << LoadError(dangling);
  EXPECT_THROW(LoadOrCreateKey(At(dangling)), KeyFileError);
  EXPECT_FALSE(fs::exists(Path("nothing")));
  // The real path loads.
  EXPECT_EQ(LoadError(real), "");
}

TEST_F(KeyFileTest, KeyOwnedByAnotherUserIsRefusedWithChown) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root to give a file to another user";
  const passwd* nobody = getpwnam("nobody");
  ASSERT_NE(nobody, nullptr);
  const std::string path = Path("session.key");
  WriteBytes(path, 32, 0600);
  ASSERT_EQ(chown(path.c_str(), nobody->pw_uid, nobody->pw_gid), 0);
  const std::string error = LoadError(path);
  EXPECT_NE(error.find(path), std::string::npos) << error;
  EXPECT_NE(error.find("owned by nobody"), std::string::npos) << error;
  EXPECT_NE(error.find("chown root " + path), std::string::npos) << error;
}

TEST_F(KeyFileTest, GroupOrWorldWritableDirectoryIsRefusedWithChmodGoW) {
  const std::string sub = Path("shared");
  ASSERT_TRUE(fs::create_directory(sub));
  const std::string path = sub + "/session.key";
  WriteBytes(path, 32, 0600);
  EXPECT_EQ(LoadError(path), "");
  for (const mode_t mode : {0770, 0777, 0702}) {
    ASSERT_EQ(chmod(sub.c_str(), mode), 0);
    const std::string error = LoadError(path);
    EXPECT_NE(error.find("chmod go-w " + sub), std::string::npos) << error;
    EXPECT_NE(error.find(path), std::string::npos) << error;
  }
  // A shared directory like /tmp (sticky) must stay writable: the fix moves the key.
  ASSERT_EQ(chmod(sub.c_str(), 01777), 0);
  const std::string error = LoadError(path);
  EXPECT_EQ(error.find("chmod go-w"), std::string::npos) << error;
  EXPECT_NE(error.find("mkdir -m 700"), std::string::npos) << error;
  // Neither keygen nor --create-key writes a key there.
  const std::string fresh = sub + "/new.key";
  EXPECT_THROW(WriteNewKey(At(fresh), false), KeyFileError);
  EXPECT_THROW(LoadOrCreateKey(At(fresh)), KeyFileError);
  EXPECT_FALSE(fs::exists(fresh));
  ASSERT_EQ(chmod(sub.c_str(), 0700), 0);
  EXPECT_EQ(LoadError(path), "");
}

TEST_F(KeyFileTest, DirectoryOwnedByAnotherUserIsRefused) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root to give a directory to another user";
  const passwd* nobody = getpwnam("nobody");
  ASSERT_NE(nobody, nullptr);
  const std::string sub = Path("theirs");
  ASSERT_TRUE(fs::create_directory(sub));
  const std::string path = sub + "/session.key";
  WriteBytes(path, 32, 0600);
  ASSERT_EQ(chown(sub.c_str(), nobody->pw_uid, nobody->pw_gid), 0);
  const std::string error = LoadError(path);
  EXPECT_NE(error.find("owned by nobody"), std::string::npos) << error;
  EXPECT_NE(error.find("chown root " + sub), std::string::npos) << error;
}

TEST_F(KeyFileTest, DirectoryIsRefused) {
  const std::string error = LoadError(dir_);
  EXPECT_NE(error.find(dir_ + " (--key) is a directory"), std::string::npos) << error;
}

TEST_F(KeyFileTest, FifoIsRefusedWithoutWaitingForAWriter) {
  const std::string path = Path("fifo");
  ASSERT_EQ(mkfifo(path.c_str(), 0600), 0);
  const std::string error = LoadError(path);  // would block forever without O_NONBLOCK
  EXPECT_NE(error.find("not a regular file"), std::string::npos) << error;
}

TEST_F(KeyFileTest, DeviceFileIsRefused) {
  EXPECT_NE(LoadError("/dev/zero").find("not a regular file"), std::string::npos);
}

// ---- creation ------------------------------------------------------------------------

TEST_F(KeyFileTest, LoadOrCreateMakesKeyWithMode0600InParents0700) {
  // Whatever the umask, the key is 0600 and the new directories 0700.
  const mode_t old_umask = umask(0);
  const std::string path = Path("config/snapthread/session.key");
  const LoadedKey made = LoadOrCreateKey(At(path));
  umask(old_umask);
  EXPECT_TRUE(made.created);
  EXPECT_EQ(ModeOf(path), 0600u);
  EXPECT_EQ(fs::file_size(path), 32u);
  EXPECT_EQ(ModeOf(Path("config")), 0700u);
  EXPECT_EQ(ModeOf(Path("config/snapthread")), 0700u);
  // No temporary file is left next to it.
  EXPECT_EQ(std::distance(fs::directory_iterator(Path("config/snapthread")), fs::directory_iterator{}), 1);

  const LoadedKey again = LoadOrCreateKey(At(path));
  EXPECT_FALSE(again.created);
  EXPECT_EQ(again.key.Id(), made.key.Id());
  EXPECT_EQ(LoadKey(At(path)).Id(), made.key.Id());
}

TEST_F(KeyFileTest, LoadOrCreateNeverReplacesAnUnusableKey) {
  const std::string path = Path("session.key");
  WriteBytes(path, 32, 0644);
  EXPECT_THROW(LoadOrCreateKey(At(path)), KeyFileError);
  EXPECT_EQ(ModeOf(path), 0644u);
  WriteBytes(path, 7, 0600);
  EXPECT_THROW(LoadOrCreateKey(At(path)), KeyFileError);
  EXPECT_EQ(fs::file_size(path), 7u);
}

TEST_F(KeyFileTest, ConcurrentCreatorsAllEndUpWithOneKey) {
  for (int round = 0; round < 5; ++round) {
    const std::string path = Path("race" + std::to_string(round) + "/session.key");
    std::vector<std::string> ids(6);
    std::vector<std::thread> threads;
    for (size_t i = 0; i < ids.size(); ++i) {
      threads.emplace_back([&, i] { ids[i] = LoadOrCreateKey(At(path)).key.Id(); });
    }
    for (auto& t : threads) t.join();
    for (const auto& id : ids) EXPECT_EQ(id, LoadKey(At(path)).Id());
  }
}

TEST_F(KeyFileTest, WriteNewKeyRefusesToOverwriteWithoutForce) {
  const std::string path = Path("k/session.key");
  WriteNewKey(At(path), false);
  const std::string first = LoadKey(At(path)).Id();
  try {
    WriteNewKey(At(path), false);
    ADD_FAILURE() << "an existing key was overwritten";
  } catch (const KeyFileError& e) {
    EXPECT_NE(std::string(e.what()).find("--force"), std::string::npos) << e.what();
  }
  EXPECT_EQ(LoadKey(At(path)).Id(), first);
  // --force replaces it (a new random key), also a badly-moded one.
  ASSERT_EQ(chmod(path.c_str(), 0644), 0);
  WriteNewKey(At(path), true);
  EXPECT_NE(LoadKey(At(path)).Id(), first);
  EXPECT_EQ(ModeOf(path), 0600u);
}

TEST_F(KeyFileTest, KeygenToolWritesKeyAndPrintsTheCopyCommand) {
  const std::string bin = SNAPTHREAD_TEST_BIN_DIR;
  const std::string path = Path("tool/session.key");
  const std::string out = Path("out.txt");
  const std::string cmd = bin + "/snapthread-keygen --host labpc --key " + path + " > " + out + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  std::ifstream in(out);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find(path), std::string::npos) << text;
  EXPECT_NE(text.find("scp -p " + path + " labpc:.config/snapthread/session.key"), std::string::npos)
      << text;
  EXPECT_NE(text.find(LoadKey(At(path)).Id()), std::string::npos) << text;
  EXPECT_EQ(ModeOf(path), 0600u);
  // A second run refuses (exit status 1) and keeps the key; --force replaces it.
  const std::string id = LoadKey(At(path)).Id();
  EXPECT_EQ(std::system(cmd.c_str()), 1 << 8);
  EXPECT_EQ(LoadKey(At(path)).Id(), id);
  EXPECT_EQ(std::system((cmd + " --force").c_str()), 0);
  EXPECT_NE(LoadKey(At(path)).Id(), id);
}

}  // namespace
}  // namespace snapthread::auth
