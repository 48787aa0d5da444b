#include "renders/gl_context.hpp"

#include <cstdlib>
#include <cstring>
#include <vector>

#include "renders/gl_api.hpp"

namespace driftless::render {

// the default framebuffer is tiny: MuJoCo renders into its own off-screen FBO (mjFB_OFFSCREEN)
struct GlContext::Impl {
  OSMesaContext ctx = nullptr;
  std::vector<unsigned char> window_rgba = std::vector<unsigned char>(64 * 64 * 4);
};

GlContext::GlContext() : impl_(std::make_unique<Impl>()) {
  const char* no_gl = std::getenv(kNoGlEnv);
  if (no_gl != nullptr && std::strcmp(no_gl, "") != 0 && std::strcmp(no_gl, "0") != 0) {
    throw GlUnavailable(std::string("no OpenGL context: disabled by ") + kNoGlEnv + "=" + no_gl +
                        " (unset it to render)");
  }
  const GlApi& api = gl_api();
  // 24-bit depth and 8-bit stencil, as MuJoCo's renderer expects
  impl_->ctx = api.CreateContextExt(OSMESA_RGBA, 24, 8, 0, nullptr);
  if (impl_->ctx == nullptr) {
    throw GlUnavailable(
        "no OpenGL context: OSMesaCreateContextExt refused an RGBA context with 24-bit depth "
        "and 8-bit stencil (libOSMesa loaded; is it Mesa's, with the gallium llvmpipe driver?)");
  }
  if (!api.MakeCurrent(impl_->ctx, impl_->window_rgba.data(), GL_UNSIGNED_BYTE, 64, 64)) {
    api.DestroyContext(impl_->ctx);
    impl_->ctx = nullptr;
    throw GlUnavailable("no OpenGL context: OSMesaMakeCurrent failed");
  }
}

GlContext::~GlContext() {
  if (impl_ && impl_->ctx != nullptr) gl_api().DestroyContext(impl_->ctx);
}

std::string GlContext::renderer() const {
  const auto* s = reinterpret_cast<const char*>(gl_api().GetString(GL_RENDERER));
  return s != nullptr ? std::string(s) : std::string("unknown");
}

}  // namespace driftless::render
