// Where rendered frames go: an H.264 MP4 through the ffmpeg program (raw RGB piped to its stdin),
// or, when ffmpeg is missing, a numbered PNG sequence (libpng).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

namespace driftless::render {

/// Environment variable naming the ffmpeg program (default "ffmpeg", looked up on PATH).
inline constexpr const char* kFfmpegEnv = "DRIFTLESS_FFMPEG";

/// Encoder settings for the MP4 path.
struct EncoderParams {
  std::string preset = "ultrafast";  // x264 preset: ultrafast keeps 640x480@30 above real time
  int crf = 23;                      // x264 constant rate factor (0 lossless .. 51 worst)

  /// Throws std::invalid_argument on an unknown preset or a crf outside 0..51.
  void validate() const;
};

/// Receives frames of width*height RGB bytes, rows top to bottom.
class VideoSink {
 public:
  virtual ~VideoSink() = default;
  /// Writes one frame; throws std::runtime_error if the encoder died (with its message).
  virtual void write(const std::uint8_t* rgb_top_down) = 0;
  /// Finishes the file(s); throws std::runtime_error if the encoder failed.
  virtual void close() = 0;
  /// What was written, for the user ("video.mp4" or "video_frames/frame_%06d.png").
  virtual std::string description() const = 0;
  virtual std::uint64_t frames_written() const = 0;
};

/// The ffmpeg program to use (kFfmpegEnv or "ffmpeg") resolved on PATH, or empty when not found.
std::filesystem::path find_ffmpeg();

/// The MP4 sink: spawns ffmpeg (libx264, yuv420p) and pipes raw frames; width/height even.
std::unique_ptr<VideoSink> make_ffmpeg_sink(const std::filesystem::path& ffmpeg,
                                            const std::filesystem::path& out, int width,
                                            int height, double fps, const EncoderParams& enc);

/// The fallback sink: `dir/frame_000000.png`, `frame_000001.png`, ... (dir is created).
std::unique_ptr<VideoSink> make_png_sink(const std::filesystem::path& dir, int width, int height);

/// The folder the PNG fallback uses for `out` ("run.mp4" -> "run_frames").
std::filesystem::path png_fallback_dir(const std::filesystem::path& out);

}  // namespace driftless::render
