// The one output helper: temporary name, checked writes, rename; a failure leaves nothing that
// looks complete and says "<file>: <reason>".
#include <sys/mount.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "estimator/output_file.hpp"

namespace driftless::io {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("driftless_test_output_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::size_t files_in(const fs::path& dir) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}

// a 64 KiB tmpfs: a real "No space left on device" (needs root; skipped elsewhere)
class SmallDisk {
 public:
  explicit SmallDisk(const fs::path& dir) : dir_(dir) {
    mounted_ = ::mount("tmpfs", dir.c_str(), "tmpfs", 0, "size=64k") == 0;
  }
  ~SmallDisk() {
    if (mounted_) ::umount(dir_.c_str());
  }
  bool mounted() const { return mounted_; }

 private:
  fs::path dir_;
  bool mounted_ = false;
};

TEST(OutputFile, CommitRenamesThePartialFileOverTheTarget) {
  const fs::path dir = fresh_dir("commit");
  const fs::path target = dir / "summary.json";
  OutputFile f(target);
  EXPECT_EQ(f.partial().parent_path(), dir);
  EXPECT_EQ(f.partial().extension(), ".json");  // programs choosing a format by extension still can
  f.write("{\"complete\": true}\n");
  EXPECT_FALSE(fs::exists(target));
  EXPECT_TRUE(fs::exists(f.partial()));
  f.commit();
  EXPECT_EQ(read_text(target), "{\"complete\": true}\n");
  EXPECT_EQ(files_in(dir), 1u);
}

TEST(OutputFile, UncommittedOutputLeavesNothingAndRemovesAnEarlierResult) {
  const fs::path dir = fresh_dir("uncommitted");
  const fs::path target = dir / "estimate.csv";
  std::ofstream(target) << "an earlier run's result\n";
  {
    OutputFile f(target);
    EXPECT_FALSE(fs::exists(target));  // a stale result never passes for this run's
    for (int i = 0; i < 100000; ++i) f.write("1.0000000,2.0000000\n");  // > one buffer: bytes on disk
  }
  EXPECT_EQ(files_in(dir), 0u);
}

TEST(OutputFile, WriteFileWritesLargeContentExactly) {
  const fs::path dir = fresh_dir("large");
  std::string text;
  for (int i = 0; i < 300000; ++i) text += std::to_string(i) + "\n";
  write_file(dir / "big.csv", text);
  EXPECT_EQ(read_text(dir / "big.csv"), text);
}

TEST(OutputFile, MissingFolderIsOneLineNamingTheTarget) {
  const fs::path target = fresh_dir("missing") / "no" / "such" / "out.csv";
  try {
    OutputFile f(target);
    FAIL() << "expected OutputError";
  } catch (const OutputError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind(target.string() + ": cannot open for writing: No such file or directory", 0), 0u) << m;
  }
}

TEST(OutputFile, FullDiskThrowsNamingTheTargetAndLeavesNothing) {
  const fs::path dir = fresh_dir("full");
  SmallDisk disk(dir);
  if (!disk.mounted()) GTEST_SKIP() << "cannot mount a 64 KiB tmpfs here (needs root); full disk untested";
  const fs::path target = dir / "corrected.csv";
  std::string what;
  try {
    OutputFile f(target);
    for (int i = 0; i < 20000; ++i) f.write("12345.6789012,12345.6789012,12345.6789012\n");
    f.commit();
  } catch (const OutputError& e) {
    what = e.what();
  }
  EXPECT_EQ(what, target.string() + ": No space left on device");
  EXPECT_EQ(files_in(dir), 0u);
}

TEST(CheckedFile, DevFullFailsOnFlushNamingTheFile) {
  CheckedFile f("/dev/full", "wb", "shown.csv");
  f.write("x");  // buffered by the C library
  try {
    f.flush();
    FAIL() << "expected OutputError";
  } catch (const OutputError& e) {
    EXPECT_STREQ(e.what(), "shown.csv: No space left on device");
  }
}

TEST(ExternalOutput, CommitsOnlyANonEmptyFile) {
  const fs::path dir = fresh_dir("external");
  {
    ExternalOutput png(dir / "fig.png");
    EXPECT_EQ(png.partial().extension(), ".png");
    std::ofstream(png.partial()) << "";  // the program wrote an empty file
    try {
      png.commit("gnuplot");
      FAIL() << "expected OutputError";
    } catch (const OutputError& e) {
      EXPECT_EQ(std::string(e.what()), (dir / "fig.png").string() + ": gnuplot wrote an empty file");
    }
  }
  EXPECT_EQ(files_in(dir), 0u);
  {
    ExternalOutput mp4(dir / "video.mp4");
    try {
      mp4.commit("ffmpeg");
      FAIL() << "expected OutputError";
    } catch (const OutputError& e) {
      EXPECT_EQ(std::string(e.what()), (dir / "video.mp4").string() + ": ffmpeg wrote nothing");
    }
  }
  ExternalOutput svg(dir / "fig.svg");
  std::ofstream(svg.partial()) << "<svg/>";
  svg.commit("gnuplot");
  EXPECT_EQ(read_text(dir / "fig.svg"), "<svg/>");
  EXPECT_EQ(files_in(dir), 1u);
}

TEST(FreeBytes, FindsTheNearestExistingFolder) {
  const fs::path dir = fresh_dir("space");
  const std::int64_t here = free_bytes(dir);
  EXPECT_GT(here, 0);
  EXPECT_GT(free_bytes(dir / "not" / "yet" / "created"), 0);
}

}  // namespace
}  // namespace driftless::io
