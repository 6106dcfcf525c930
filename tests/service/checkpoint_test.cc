// The checkpoint file (server/checkpoint.h, issue 12 item 5): a round trip, every kind of
// damage refused with its reason (and every single flipped byte and every truncation
// refused), a file not written with the session key refused, the atomic write (a crash
// between the write and the rename leaves the previous file valid), the file checks of
// the reader, and the writer thread.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "auth/file_mac.h"
#include "auth/session_key.h"
#include "checkpoint.h"
#include "checkpoint_writer.h"
#include "environment.h"
#include "temp_dir.h"

namespace snapthread::server {
namespace {

Checkpoint Sample() {
  Checkpoint c;
  c.utime = 1764040000123456;
  c.epoch = static_cast<int64_t>(0x8123456789abcdefULL);
  c.seq = 42;
  c.scene_name = "curve2d_snap";
  c.scene_file = "/somewhere/scenes/curve2d_snap.yaml";
  c.scene_text = "name: curve2d_snap\nmodel: curve2d\n# \xc3\xa9 and a NUL \0 inside\n";
  c.scene_text += std::string(1, '\0') + "tail";
  c.method = "higher-order";
  c.u = (Vec(2) << 9.0, 2.4).finished();
  c.x = Vec::LinSpaced(17, -1.0, 1.0);
  c.x[3] = -0.0;
  c.x[4] = std::numeric_limits<double>::denorm_min();
  return c;
}

// Recomputes the checksum and the tag after a test edited the bytes, as a writer holding
// the key would: the payload checks behind them are then what refuses the file.
std::string Reseal(std::string bytes, const auth::SessionKey& key) {
  const size_t body = bytes.size() - kCheckpointTrailerBytes;
  uint8_t sum[auth::kFileChecksumBytes];
  auth::FileChecksum(bytes.data(), body, sum);
  std::memcpy(bytes.data() + body, sum, sizeof(sum));
  uint8_t tag[auth::kFileMacBytes];
  auth::FileMac("checkpoint", bytes.data(), body + sizeof(sum), key, tag);
  std::memcpy(bytes.data() + body + sizeof(sum), tag, sizeof(tag));
  return bytes;
}

void PutU32At(std::string* bytes, size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) (*bytes)[at + i] = static_cast<char>((v >> (8 * i)) & 0xff);
}

std::string Refusal(const std::string& bytes, const auth::SessionKey& key) {
  std::string reason;
  Checkpoint out;
  EXPECT_FALSE(DecodeCheckpoint(bytes, key, &out, &reason));
  return reason;
}

class CheckpointFormatTest : public ::testing::Test {
 protected:
  auth::SessionKey key_ = auth::SessionKey::Generate();
};

TEST_F(CheckpointFormatTest, RoundTripKeepsEveryFieldBitForBit) {
  const Checkpoint c = Sample();
  const std::string bytes = EncodeCheckpoint(c, key_);
  EXPECT_EQ(bytes.substr(0, 8), "SNAPCKPT");
  Checkpoint out;
  std::string reason;
  ASSERT_TRUE(DecodeCheckpoint(bytes, key_, &out, &reason)) << reason;
  EXPECT_EQ(out.utime, c.utime);
  EXPECT_EQ(out.epoch, c.epoch);
  EXPECT_EQ(out.seq, c.seq);
  EXPECT_EQ(out.scene_name, c.scene_name);
  EXPECT_EQ(out.scene_file, c.scene_file);
  EXPECT_EQ(out.scene_text, c.scene_text);
  EXPECT_EQ(out.method, c.method);
  ASSERT_EQ(out.u.size(), c.u.size());
  ASSERT_EQ(out.x.size(), c.x.size());
  EXPECT_EQ(std::memcmp(out.u.data(), c.u.data(), sizeof(double) * c.u.size()), 0);
  EXPECT_EQ(std::memcmp(out.x.data(), c.x.data(), sizeof(double) * c.x.size()), 0);
  EXPECT_TRUE(std::signbit(out.x[3]));
}

TEST_F(CheckpointFormatTest, EmptyStateAndSceneRoundTrip) {
  Checkpoint c;
  c.method = "newton";
  Checkpoint out;
  std::string reason;
  ASSERT_TRUE(DecodeCheckpoint(EncodeCheckpoint(c, key_), key_, &out, &reason)) << reason;
  EXPECT_EQ(out.x.size(), 0);
  EXPECT_EQ(out.method, "newton");
}

TEST_F(CheckpointFormatTest, EachKindOfDamageIsRefusedWithItsReason) {
  const std::string good = EncodeCheckpoint(Sample(), key_);
  EXPECT_NE(Refusal("", key_).find("truncated: 0 bytes"), std::string::npos);
  EXPECT_NE(Refusal(good.substr(0, 10), key_).find("shorter than the 16-byte header"), std::string::npos);
  EXPECT_NE(Refusal(good.substr(0, good.size() - 1), key_).find("truncated"), std::string::npos);
  EXPECT_NE(Refusal(good + "x", key_).find("wrong length"), std::string::npos);

  std::string magic = good;
  magic[0] = 'X';
  EXPECT_EQ(Refusal(magic, key_), "bad magic (not a snapthread checkpoint)");

  std::string version = good;
  PutU32At(&version, 8, 2);
  EXPECT_NE(Refusal(Reseal(version, key_), key_).find("unsupported version 2"), std::string::npos);

  std::string length = good;
  PutU32At(&length, 12, static_cast<uint32_t>(good.size()));  // header lies about P
  EXPECT_NE(Refusal(length, key_).find("the header says"), std::string::npos);

  std::string flipped = good;
  flipped[kCheckpointHeaderBytes + 30] ^= 0x01;
  EXPECT_EQ(Refusal(flipped, key_), "checksum mismatch (the file is damaged)");

  // Intact, but written with another key (someone without the session key).
  const auth::SessionKey other = auth::SessionKey::Generate();
  EXPECT_NE(Refusal(EncodeCheckpoint(Sample(), other), key_).find("not written with this session key"),
            std::string::npos);
  // An intact file with its tag replaced by the checksum of a forger's edit.
  std::string forged = good;
  forged[kCheckpointHeaderBytes + 30] ^= 0x01;
  const size_t body = forged.size() - kCheckpointTrailerBytes;
  uint8_t sum[auth::kFileChecksumBytes];
  auth::FileChecksum(forged.data(), body, sum);
  std::memcpy(forged.data() + body, sum, sizeof(sum));
  EXPECT_NE(Refusal(forged, key_).find("bad MAC"), std::string::npos);
}

TEST_F(CheckpointFormatTest, NonFiniteValuesAreRefusedNamingTheEntry) {
  for (const double bad : {std::nan(""), std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity()}) {
    Checkpoint c = Sample();
    c.x[5] = bad;
    const std::string reason = Refusal(EncodeCheckpoint(c, key_), key_);
    EXPECT_NE(reason.find("non-finite value in the state x[5]"), std::string::npos) << reason;
    c = Sample();
    c.u[1] = bad;
    EXPECT_NE(Refusal(EncodeCheckpoint(c, key_), key_).find("grasp u[1]"), std::string::npos);
  }
}

TEST_F(CheckpointFormatTest, AMalformedPayloadBehindAValidTagIsRefused) {
  const Checkpoint c = Sample();
  const std::string good = EncodeCheckpoint(c, key_);
  // The scene name's length (after utime, epoch, seq) claims more bytes than there are.
  std::string overrun = good;
  PutU32At(&overrun, kCheckpointHeaderBytes + 24, 0x7fffffff);
  EXPECT_NE(Refusal(Reseal(overrun, key_), key_).find("malformed payload"), std::string::npos);
  // The state's count says one double fewer: 8 bytes are left over.
  std::string extra = good;
  const size_t x_count_at =
      good.size() - kCheckpointTrailerBytes - 8 * static_cast<size_t>(c.x.size()) - 4;
  PutU32At(&extra, x_count_at, static_cast<uint32_t>(c.x.size() - 1));
  EXPECT_NE(Refusal(Reseal(extra, key_), key_).find("8 bytes after the state"), std::string::npos);
}

TEST_F(CheckpointFormatTest, EverySingleFlippedBitAndEveryTruncationIsRefused) {
  const std::string good = EncodeCheckpoint(Sample(), key_);
  for (size_t i = 0; i < good.size(); ++i) {
    for (const int bit : {0, 7}) {
      std::string bad = good;
      bad[i] = static_cast<char>(bad[i] ^ (1 << bit));
      std::string reason;
      EXPECT_FALSE(DecodeCheckpoint(bad, key_, nullptr, &reason)) << "byte " << i << " bit " << bit;
      EXPECT_FALSE(reason.empty());
    }
  }
  for (size_t n = 0; n < good.size(); ++n) {
    std::string reason;
    EXPECT_FALSE(DecodeCheckpoint(good.substr(0, n), key_, nullptr, &reason)) << n << " bytes";
    EXPECT_NE(reason.find("truncated"), std::string::npos) << n << ": " << reason;
  }
}

// ---------------------------------------------------------------- files

class CheckpointFileTest : public CheckpointFormatTest {
 protected:
  std::string Path() const { return CheckpointPath(dir_.path(), "S1"); }
  Checkpoint Read() {
    std::string bytes, reason;
    EXPECT_EQ(ReadCheckpointFile(Path(), &bytes, &reason), ReadStatus::kOk) << reason;
    Checkpoint c;
    EXPECT_TRUE(DecodeCheckpoint(bytes, key_, &c, &reason)) << reason;
    return c;
  }
  test_support::ScopedTempDir dir_{"checkpoint"};
};

TEST_F(CheckpointFileTest, PathIsPerSessionInTheStateDir) {
  EXPECT_EQ(CheckpointPath("/var/lib/snapthread", "LAB_A"), "/var/lib/snapthread/LAB_A.checkpoint");
}

TEST_F(CheckpointFileTest, ACrashBetweenWriteAndRenameLeavesThePreviousFileValid) {
  Checkpoint first = Sample();
  first.seq = 1;
  WriteFileAtomically(Path(), EncodeCheckpoint(first, key_));
  struct stat info {};
  ASSERT_EQ(::stat(Path().c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0600u);

  // The next checkpoint is written and synced to the temp file; the process dies before
  // the rename (CommitTempFile never runs).
  Checkpoint second = Sample();
  second.seq = 2;
  second.x[0] = 123.0;
  WriteTempFile(Path(), EncodeCheckpoint(second, key_));
  ASSERT_EQ(::stat((Path() + ".tmp").c_str(), &info), 0);
  EXPECT_EQ(Read().seq, 1);
  EXPECT_EQ(Read().x[0], first.x[0]);

  // A torn temp file (the crash came during the write) changes nothing either.
  std::ofstream(Path() + ".tmp", std::ios::trunc) << "SNAPCKPT\x01";
  EXPECT_EQ(Read().seq, 1);

  // The restarted server's next write replaces the stale temp file and commits.
  Checkpoint third = Sample();
  third.seq = 3;
  WriteFileAtomically(Path(), EncodeCheckpoint(third, key_));
  EXPECT_EQ(Read().seq, 3);
  EXPECT_NE(::stat((Path() + ".tmp").c_str(), &info), 0) << "the temp file was renamed";
}

TEST_F(CheckpointFileTest, ReaderRefusesWhatIsNotARegularFile) {
  std::string bytes, reason;
  EXPECT_EQ(ReadCheckpointFile(Path(), &bytes, &reason), ReadStatus::kMissing);

  ASSERT_EQ(::symlink("/etc/passwd", Path().c_str()), 0);
  EXPECT_EQ(ReadCheckpointFile(Path(), &bytes, &reason), ReadStatus::kRefused);
  EXPECT_NE(reason.find("symbolic link"), std::string::npos) << reason;
  ASSERT_EQ(::unlink(Path().c_str()), 0);

  ASSERT_EQ(::mkfifo(Path().c_str(), 0600), 0);
  EXPECT_EQ(ReadCheckpointFile(Path(), &bytes, &reason), ReadStatus::kRefused);
  EXPECT_EQ(reason, "not a regular file");
  ASSERT_EQ(::unlink(Path().c_str()), 0);

  ASSERT_EQ(::mkdir(Path().c_str(), 0700), 0);
  EXPECT_EQ(ReadCheckpointFile(Path(), &bytes, &reason), ReadStatus::kRefused);
  ASSERT_EQ(::rmdir(Path().c_str()), 0);

  // Larger than any checkpoint: refused from its size, without reading it.
  {
    const int fd = ::open(Path().c_str(), O_WRONLY | O_CREAT, 0600);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::ftruncate(fd, static_cast<off_t>(kMaxCheckpointBytes) + 1), 0);
    ::close(fd);
  }
  EXPECT_EQ(ReadCheckpointFile(Path(), &bytes, &reason), ReadStatus::kRefused);
  EXPECT_NE(reason.find("too large"), std::string::npos) << reason;
}

TEST_F(CheckpointFileTest, StateDirIsMadeOrRefusedWithTheReason) {
  const std::string made = dir_.path() + "/state";
  PrepareStateDir(made);
  struct stat info {};
  ASSERT_EQ(::stat(made.c_str(), &info), 0);
  EXPECT_TRUE(S_ISDIR(info.st_mode));
  EXPECT_EQ(info.st_mode & 0777, 0700u);
  PrepareStateDir(made);  // exists: fine

  const std::string file = dir_.path() + "/plain";
  std::ofstream(file) << "x";
  try {
    PrepareStateDir(file);
    ADD_FAILURE() << "a file was accepted as --state-dir";
  } catch (const CheckpointIoError& e) {
    EXPECT_NE(std::string(e.what()).find("--state-dir: " + file + " is not a directory"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(PrepareStateDir(dir_.path() + "/missing/parent"), CheckpointIoError);
}

TEST_F(CheckpointFileTest, WriterCommitsTheNewestSnapshot) {
  {
    CheckpointWriter writer(Path(), key_);
    for (int i = 1; i <= 200; ++i) {
      Checkpoint c = Sample();
      c.seq = i;
      writer.Offer(std::move(c));
    }
    writer.Flush();
    const CheckpointWriterStats s = writer.Stats();
    EXPECT_EQ(s.offered, 200);
    EXPECT_GE(s.written, 1);
    EXPECT_LE(s.written, 200);  // a slow disk skips to the newest
    EXPECT_EQ(s.failed, 0);
    EXPECT_GT(s.write_us_p50, 0.0);
    EXPECT_EQ(Read().seq, 200);
  }
  // A write that fails (the directory is gone) is counted, and the writer goes on.
  test_support::ScopedTempDir gone("checkpoint-gone");
  const std::string path = gone.path() + "/sub/S1.checkpoint";
  CheckpointWriter writer(path, key_);
  writer.Offer(Sample());
  writer.Flush();
  EXPECT_EQ(writer.Stats().failed, 1);
  EXPECT_EQ(writer.Stats().written, 0);
}

}  // namespace
}  // namespace snapthread::server
