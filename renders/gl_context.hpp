// An OSMesa off-screen OpenGL context: software rendering with no display and no GPU.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

namespace driftless::render {

/// No GL context could be made (OSMesa missing or refused, or forced off for tests).
class GlUnavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Environment variable that makes context creation fail (tests of the error path): set to 1.
inline constexpr const char* kNoGlEnv = "DRIFTLESS_RENDER_NO_GL";

/// Owns an OSMesa context and its small default framebuffer, current on the creating thread.
/// MuJoCo draws into its own off-screen framebuffer object inside this context.
class GlContext {
 public:
  /// Creates the context and makes it current; throws GlUnavailable with the reason.
  GlContext();
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  /// The GL_RENDERER string (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)").
  std::string renderer() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace driftless::render
