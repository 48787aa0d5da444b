#include "renders/gl_api.hpp"

#include <dlfcn.h>

#include <string>

#include "renders/gl_context.hpp"

namespace driftless::render {
namespace {

// Debian's libosmesa6 ships the versioned name; the plain name comes with the -dev package
constexpr const char* kLibraryNames[] = {"libOSMesa.so.8", "libOSMesa.so"};

void* open_library() {
  std::string errors;
  for (const char* name : kLibraryNames) {
    if (void* h = dlopen(name, RTLD_NOW | RTLD_GLOBAL)) return h;
    const char* e = dlerror();
    errors += std::string("; ") + (e != nullptr ? e : name);
  }
  throw GlUnavailable("no OpenGL context: cannot load Mesa's libOSMesa (Debian: libosmesa6)" + errors);
}

template <class Fn>
void resolve(void* lib, Fn& fn, const char* symbol) {
  fn = reinterpret_cast<Fn>(dlsym(lib, symbol));
  if (fn == nullptr) {
    throw GlUnavailable(std::string("no OpenGL context: libOSMesa has no ") + symbol +
                        " (an OSMesa older than Mesa 7.x?)");
  }
}

GlApi load() {
  void* lib = open_library();  // kept loaded for the life of the process, as MuJoCo holds pointers
  GlApi api;
  resolve(lib, api.CreateContextExt, "OSMesaCreateContextExt");
  resolve(lib, api.MakeCurrent, "OSMesaMakeCurrent");
  resolve(lib, api.DestroyContext, "OSMesaDestroyContext");
  resolve(lib, api.GetString, "glGetString");
  resolve(lib, api.Begin, "glBegin");
  resolve(lib, api.End, "glEnd");
  resolve(lib, api.Vertex2f, "glVertex2f");
  resolve(lib, api.Color4f, "glColor4f");
  resolve(lib, api.Enable, "glEnable");
  resolve(lib, api.Disable, "glDisable");
  resolve(lib, api.LineWidth, "glLineWidth");
  resolve(lib, api.LineStipple, "glLineStipple");
  resolve(lib, api.Viewport, "glViewport");
  resolve(lib, api.Scissor, "glScissor");
  resolve(lib, api.MatrixMode, "glMatrixMode");
  resolve(lib, api.LoadIdentity, "glLoadIdentity");
  resolve(lib, api.Ortho, "glOrtho");
  resolve(lib, api.BlendFunc, "glBlendFunc");
  return api;
}

}  // namespace

const GlApi& gl_api() {
  static const GlApi api = load();  // a failed load throws and is retried on the next call
  return api;
}

}  // namespace driftless::render
