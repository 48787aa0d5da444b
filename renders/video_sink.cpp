#include "renders/video_sink.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/core.h>
#include <png.h>

#include "estimator/output_file.hpp"

extern char** environ;

namespace driftless::render {

void EncoderParams::validate() const {
  static constexpr std::array<const char*, 10> kPresets = {
      "ultrafast", "superfast", "veryfast", "faster", "fast",
      "medium",    "slow",      "slower",   "veryslow", "placebo"};
  if (std::none_of(kPresets.begin(), kPresets.end(),
                   [&](const char* p) { return preset == p; })) {
    throw std::invalid_argument(
        fmt::format("encoder preset '{}' is not an x264 preset (ultrafast, superfast, veryfast, "
                    "faster, fast, medium, slow, slower, veryslow, placebo)",
                    preset));
  }
  if (crf < 0 || crf > 51) {
    throw std::invalid_argument(fmt::format("encoder crf {} is outside 0..51", crf));
  }
}

std::filesystem::path find_ffmpeg() {
  const char* env = std::getenv(kFfmpegEnv);
  const std::string name = (env != nullptr && *env != '\0') ? env : "ffmpeg";
  auto runnable = [](const std::filesystem::path& p) {
    return ::access(p.c_str(), X_OK) == 0 && !std::filesystem::is_directory(p);
  };
  if (name.find('/') != std::string::npos) {
    return runnable(name) ? std::filesystem::path(name) : std::filesystem::path{};
  }
  const char* path = std::getenv("PATH");
  std::string dirs = path != nullptr ? path : "/usr/local/bin:/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= dirs.size()) {
    const std::size_t end = std::min(dirs.find(':', start), dirs.size());
    const std::string dir = dirs.substr(start, end - start);
    const auto candidate = std::filesystem::path(dir.empty() ? "." : dir) / name;
    if (runnable(candidate)) return candidate;
    start = end + 1;
  }
  return {};
}

std::filesystem::path png_fallback_dir(const std::filesystem::path& out) {
  auto dir = out;
  dir.replace_extension();
  dir += "_frames";
  return dir;
}

namespace {

// ignores SIGPIPE while a pipe to a child is open, so a dead encoder gives EPIPE, not death
class SigpipeGuard {
 public:
  SigpipeGuard() {
    struct sigaction ign {};
    ign.sa_handler = SIG_IGN;
    sigemptyset(&ign.sa_mask);
    ::sigaction(SIGPIPE, &ign, &old_);
  }
  ~SigpipeGuard() { ::sigaction(SIGPIPE, &old_, nullptr); }
  SigpipeGuard(const SigpipeGuard&) = delete;
  SigpipeGuard& operator=(const SigpipeGuard&) = delete;

 private:
  struct sigaction old_ {};
};

class FfmpegSink final : public VideoSink {
 public:
  FfmpegSink(const std::filesystem::path& ffmpeg, const std::filesystem::path& out, int width,
             int height, double fps, const EncoderParams& enc)
      : out_(out), out_file_(out), frame_bytes_(static_cast<std::size_t>(width) * height * 3) {
    enc.validate();
    if (width % 2 != 0 || height % 2 != 0 || width <= 0 || height <= 0) {
      throw std::invalid_argument(
          fmt::format("video size {}x{} px: H.264 (yuv420p) needs a positive even width and "
                      "height",
                      width, height));
    }
    const std::vector<std::string> args = {
        ffmpeg.string(), "-hide_banner", "-loglevel", "error", "-nostdin", "-y",
        "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", fmt::format("{}x{}", width, height),
        "-framerate", fmt::format("{}", fps), "-i", "pipe:0",
        "-c:v", "libx264", "-preset", enc.preset, "-crf", std::to_string(enc.crf),
        "-pix_fmt", "yuv420p", "-movflags", "+faststart", out_file_.partial().string()};
    int in_pipe[2], err_pipe[2];
    if (::pipe2(in_pipe, O_CLOEXEC) != 0 || ::pipe2(err_pipe, O_CLOEXEC) != 0) {
      throw std::runtime_error(fmt::format("cannot create a pipe for ffmpeg: {}",
                                           std::strerror(errno)));
    }
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, in_pipe[0], STDIN_FILENO);
    posix_spawn_file_actions_adddup2(&fa, err_pipe[1], STDERR_FILENO);
    posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    // its own process group: Ctrl-C reaches only us, and we close the pipe so ffmpeg finishes
    // the file properly
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
    posix_spawnattr_setpgroup(&attr, 0);
    const int rc = ::posix_spawn(&pid_, ffmpeg.c_str(), &fa, &attr, argv.data(), environ);
    posix_spawnattr_destroy(&attr);
    posix_spawn_file_actions_destroy(&fa);
    ::close(in_pipe[0]);
    ::close(err_pipe[1]);
    if (rc != 0) {
      ::close(in_pipe[1]);
      ::close(err_pipe[0]);
      throw std::runtime_error(
          fmt::format("cannot start {}: {}", ffmpeg.string(), std::strerror(rc)));
    }
    in_fd_ = in_pipe[1];
    err_fd_ = err_pipe[0];
    // drain ffmpeg's stderr so it can never block on a full pipe; keep the tail for messages
    err_reader_ = std::thread([this] {
      char buf[4096];
      ssize_t n;
      while ((n = ::read(err_fd_, buf, sizeof buf)) > 0) {
        err_text_.append(buf, static_cast<std::size_t>(n));
        if (err_text_.size() > 8192) err_text_.erase(0, err_text_.size() - 8192);
      }
    });
  }

  ~FfmpegSink() override {
    try {
      close();
    } catch (...) {
      // destructors never throw; close() reports errors to callers that call it
    }
  }

  void write(const std::uint8_t* rgb) override {
    std::size_t left = frame_bytes_;
    const std::uint8_t* p = rgb;
    while (left > 0) {
      const ssize_t n = ::write(in_fd_, p, left);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        const std::string why = std::strerror(errno);
        close_pipe_and_wait();
        throw std::runtime_error(fmt::format("ffmpeg stopped taking frames ({}): {}", why,
                                             error_tail()));
      }
      left -= static_cast<std::size_t>(n);
      p += n;
    }
    ++frames_;
  }

  void close() override {
    if (closed_) return;
    const int status = close_pipe_and_wait();
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      throw std::runtime_error(fmt::format("ffmpeg failed writing {}: {}", out_.string(),
                                           error_tail()));
    }
    // the video is renamed into place only after ffmpeg exited 0 (a failed or killed encoder
    // leaves no file that looks playable)
    out_file_.commit("ffmpeg");
  }

  std::string description() const override { return out_.string(); }
  std::uint64_t frames_written() const override { return frames_; }

 private:
  int close_pipe_and_wait() {
    if (closed_) return status_;
    closed_ = true;
    if (in_fd_ >= 0) ::close(in_fd_);
    in_fd_ = -1;
    while (::waitpid(pid_, &status_, 0) < 0 && errno == EINTR) {
    }
    if (err_reader_.joinable()) err_reader_.join();
    ::close(err_fd_);
    return status_;
  }

  std::string error_tail() const {
    std::string t = err_text_;
    while (!t.empty() && (t.back() == '\n' || t.back() == '\r')) t.pop_back();
    if (t.empty()) return "exit status " + std::to_string(WEXITSTATUS(status_));
    std::replace(t.begin(), t.end(), '\n', ' ');
    return t;
  }

  SigpipeGuard sigpipe_;
  std::filesystem::path out_;
  io::ExternalOutput out_file_;  // ffmpeg writes its partial name
  std::size_t frame_bytes_;
  pid_t pid_ = -1;
  int in_fd_ = -1, err_fd_ = -1;
  int status_ = 0;
  bool closed_ = false;
  std::thread err_reader_;
  std::string err_text_;
  std::uint64_t frames_ = 0;
};

class PngSink final : public VideoSink {
 public:
  PngSink(const std::filesystem::path& dir, int width, int height)
      : dir_(dir), width_(width), height_(height) {
    if (width <= 0 || height <= 0) {
      throw std::invalid_argument(fmt::format("frame size {}x{} px must be positive", width,
                                              height));
    }
    std::error_code ec;
    std::filesystem::create_directories(dir_, ec);
    if (ec) {
      throw std::runtime_error(fmt::format("cannot create {}: {}", dir_.string(), ec.message()));
    }
  }

  void write(const std::uint8_t* rgb) override {
    const auto path = dir_ / fmt::format("frame_{:06d}.png", frames_);
    // a frame is written under its partial name and renamed when libpng finished it
    io::ExternalOutput out(path);
    io::CheckedFile f(out.partial(), "wb", path.string());
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
    if (png == nullptr || info == nullptr || setjmp(png_jmpbuf(png))) {
      png_destroy_write_struct(&png, &info);
      throw std::runtime_error(fmt::format("libpng failed writing {}", path.string()));
    }
    png_init_io(png, f.get());
    png_set_compression_level(png, 1);  // speed over size: these are frames, not archives
    png_set_IHDR(png, info, static_cast<png_uint_32>(width_), static_cast<png_uint_32>(height_),
                 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (int y = 0; y < height_; ++y) {
      png_write_row(png, rgb + static_cast<std::size_t>(y) * width_ * 3);
    }
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    f.close();  // throws io::OutputError "<frame>: <reason>" (a full disk)
    out.commit("libpng");
    ++frames_;
  }

  void close() override {}
  std::string description() const override {
    return (dir_ / "frame_%06d.png").string();
  }
  std::uint64_t frames_written() const override { return frames_; }

 private:
  std::filesystem::path dir_;
  int width_, height_;
  std::uint64_t frames_ = 0;
};

}  // namespace

std::unique_ptr<VideoSink> make_ffmpeg_sink(const std::filesystem::path& ffmpeg,
                                            const std::filesystem::path& out, int width,
                                            int height, double fps, const EncoderParams& enc) {
  return std::make_unique<FfmpegSink>(ffmpeg, out, width, height, fps, enc);
}

std::unique_ptr<VideoSink> make_png_sink(const std::filesystem::path& dir, int width,
                                         int height) {
  return std::make_unique<PngSink>(dir, width, height);
}

}  // namespace driftless::render
