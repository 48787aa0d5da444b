// The OpenGL entry points the renderer calls itself, resolved at run time from Mesa's libOSMesa.
// Only `render` maps the GL stack this way: libOSMesa pulls in libLLVM (about 43 MiB of resident
// pages), which every other command (simulate, estimate, diagnose, ...) paid for when it was linked.
#pragma once

#include <GL/gl.h>
#include <GL/osmesa.h>

namespace driftless::render {

/// The functions of libOSMesa used here; each pointer has the type of the header's declaration.
struct GlApi {
  decltype(&::OSMesaCreateContextExt) CreateContextExt = nullptr;
  decltype(&::OSMesaMakeCurrent) MakeCurrent = nullptr;
  decltype(&::OSMesaDestroyContext) DestroyContext = nullptr;
  decltype(&::glGetString) GetString = nullptr;
  // fixed-function drawing of the strip charts (renders/chart.cpp)
  decltype(&::glBegin) Begin = nullptr;
  decltype(&::glEnd) End = nullptr;
  decltype(&::glVertex2f) Vertex2f = nullptr;
  decltype(&::glColor4f) Color4f = nullptr;
  decltype(&::glEnable) Enable = nullptr;
  decltype(&::glDisable) Disable = nullptr;
  decltype(&::glLineWidth) LineWidth = nullptr;
  decltype(&::glLineStipple) LineStipple = nullptr;
  decltype(&::glViewport) Viewport = nullptr;
  decltype(&::glScissor) Scissor = nullptr;
  decltype(&::glMatrixMode) MatrixMode = nullptr;
  decltype(&::glLoadIdentity) LoadIdentity = nullptr;
  decltype(&::glOrtho) Ortho = nullptr;
  decltype(&::glBlendFunc) BlendFunc = nullptr;
};

/// Loads libOSMesa on first use, with its symbols global so that MuJoCo's own GL loader
/// (mjr_makeContext) finds them, and returns the table. Throws GlUnavailable naming the library,
/// the missing symbol and the loader's message when it cannot.
const GlApi& gl_api();

}  // namespace driftless::render
