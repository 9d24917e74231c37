// Test helper (not part of the product): executes the GLSL that brdf-factor
// generates for an exported factorization, on Mesa's software OpenGL
// (llvmpipe) through a surfaceless EGL context, so that a test can compare the
// shader's values with the CPU model's. Used by tests/factor/export_test.cpp.
//
//   bf_glsl_run GLSL DIRS OUT [--exact] [[SAMPLER=]TEX.exr ...]
//
// GLSL: the generated file. DIRS: one direction pair per line,
// "wi.x wi.y wi.z wo.x wo.y wo.z". OUT: one line per pair, "r g b" of
// brdf_factor_eval(wi, wo). The k-th texture is bound to the sampler SAMPLER,
// or without "SAMPLER=" to brdf_factor_texk (the homomorphic export's), exactly as
// the generated header asks: GL_RGB32F, the file's scanline 0 as the first
// row, GL_LINEAR, no mipmaps, GL_CLAMP_TO_EDGE. --exact defines
// BRDF_FACTOR_EXACT_BILINEAR (texelFetch path). Exit 1 with a message on any
// failure (no EGL display, context, compile or link error, bad input). A
// shader without textures (an analytic model's, factor/model_glsl.h) takes
// none. Also used by tests/factor/model_glsl_test.cpp and
// baseline_export_test.cpp (SAMPLER=: brdf_factor_rows, ...).
#define GL_GLEXT_PROTOTYPES
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

GLuint compile(GLenum kind, const std::string& src) {
  const GLuint s = glCreateShader(kind);
  const char* p = src.c_str();
  glShaderSource(s, 1, &p, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[8192];
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    throw std::runtime_error(std::string("shader compile failed: ") + log);
  }
  return s;
}

// A float texture of w x h RGB texels, row 0 first, nearest or linear filtering.
GLuint upload(const std::vector<float>& px, int w, int h, bool linear) {
  GLuint t = 0;
  glGenTextures(1, &t);
  glBindTexture(GL_TEXTURE_2D, t);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB32F, w, h, 0, GL_RGB, GL_FLOAT, px.data());
  const GLint f = linear ? GL_LINEAR : GL_NEAREST;
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, f);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, f);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
  return t;
}

int run(int argc, char** argv) {
  if (argc < 4) throw std::runtime_error("usage: bf_glsl_run GLSL DIRS OUT [--exact] [[SAMPLER=]TEX.exr ...]");
  const std::string glsl = read_file(argv[1]);
  int a = 4;
  bool exact = false;
  if (a < argc && std::string(argv[a]) == "--exact") exact = true, ++a;
  std::vector<std::string> textures(argv + a, argv + argc);

  // Direction pairs.
  std::vector<float> wi, wo;
  {
    std::istringstream in(read_file(argv[2]));
    double v[6];
    while (in >> v[0] >> v[1] >> v[2] >> v[3] >> v[4] >> v[5]) {
      for (int k = 0; k < 3; ++k) wi.push_back(float(v[k])), wo.push_back(float(v[3 + k]));
    }
  }
  const int n = int(wi.size() / 3);
  if (n == 0) throw std::runtime_error(std::string(argv[2]) + ": no direction pair");

  // Surfaceless EGL display (Mesa), desktop OpenGL 3.3 core context.
  auto get_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!get_display) throw std::runtime_error("EGL: eglGetPlatformDisplayEXT missing (Mesa's libegl-mesa0?)");
  EGLDisplay dpy = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  EGLint major = 0, minor = 0;
  if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, &major, &minor))
    throw std::runtime_error("EGL: no surfaceless display (Mesa's libegl-mesa0 and libgl1-mesa-dri?)");
  if (!eglBindAPI(EGL_OPENGL_API)) throw std::runtime_error("EGL: OpenGL API not available");
  const EGLint ctx_attr[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                             EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  EGLContext ctx = eglCreateContext(dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, ctx_attr);
  if (ctx == EGL_NO_CONTEXT) throw std::runtime_error("EGL: cannot create an OpenGL 3.3 core context");
  if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) throw std::runtime_error("EGL: make current failed");
  std::cerr << "bf_glsl_run: " << glGetString(GL_RENDERER) << ", OpenGL " << glGetString(GL_VERSION) << "\n";

  // One fragment per direction pair, in an n x 1 RGBA32F target.
  GLuint fbo = 0, target = 0;
  glGenTextures(1, &target);
  glBindTexture(GL_TEXTURE_2D, target);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, n, 1, 0, GL_RGBA, GL_FLOAT, nullptr);
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, target, 0);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error("GL: float framebuffer incomplete");
  glViewport(0, 0, n, 1);

  const std::string vs =
      "#version 330 core\n"
      "void main() {\n"
      "  vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);\n"
      "  gl_Position = vec4(p, 0.0, 1.0);\n"
      "}\n";
  const std::string fs = std::string("#version 330 core\n") + (exact ? "#define BRDF_FACTOR_EXACT_BILINEAR\n" : "") +
                         glsl +
                         "\nuniform sampler2D bf_run_wi;\nuniform sampler2D bf_run_wo;\n"
                         "layout(location = 0) out vec4 color;\n"
                         "void main() {\n"
                         "  ivec2 k = ivec2(int(gl_FragCoord.x), 0);\n"
                         "  color = vec4(brdf_factor_eval(texelFetch(bf_run_wi, k, 0).xyz, "
                         "texelFetch(bf_run_wo, k, 0).xyz), 1.0);\n"
                         "}\n";
  const GLuint prog = glCreateProgram();
  glAttachShader(prog, compile(GL_VERTEX_SHADER, vs));
  glAttachShader(prog, compile(GL_FRAGMENT_SHADER, fs));
  glLinkProgram(prog);
  GLint ok = 0;
  glGetProgramiv(prog, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[8192];
    glGetProgramInfoLog(prog, sizeof log, nullptr, log);
    throw std::runtime_error(std::string("program link failed: ") + log);
  }
  glUseProgram(prog);

  // Factor textures, then the two direction textures, each on its own unit.
  int unit = 0;
  for (size_t k = 0; k < textures.size(); ++k, ++unit) {
    // Read with OpenEXR itself (not the toolkit's reader): R, G, B interleaved,
    // scanline 0 first.
    std::string name = "brdf_factor_tex" + std::to_string(k), file = textures[k];
    if (const size_t eq = file.find('='); eq != std::string::npos) name = file.substr(0, eq), file = file.substr(eq + 1);
    Imf::InputFile in(file.c_str());
    const Imath::Box2i dw = in.header().dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    for (const char* ch : {"R", "G", "B"})
      if (!in.header().channels().findChannel(ch))
        throw std::runtime_error(file + ": expected channels R, G, B");
    std::vector<float> px(size_t(w) * h * 3);
    Imf::FrameBuffer fb;
    const char* names[3] = {"R", "G", "B"};
    char* base = reinterpret_cast<char*>(px.data()) - (size_t(dw.min.y) * w + dw.min.x) * 3 * sizeof(float);
    for (int c = 0; c < 3; ++c)
      fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), 3 * sizeof(float), size_t(w) * 3 * sizeof(float)));
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    glActiveTexture(GL_TEXTURE0 + unit);
    upload(px, w, h, true);  // scanline 0 = first row, GL_LINEAR
    const GLint loc = glGetUniformLocation(prog, name.c_str());
    if (loc < 0) throw std::runtime_error("GL: the shader has no sampler " + name);
    glUniform1i(loc, unit);
  }
  glActiveTexture(GL_TEXTURE0 + unit);
  upload(wi, n, 1, false);
  glUniform1i(glGetUniformLocation(prog, "bf_run_wi"), unit++);
  glActiveTexture(GL_TEXTURE0 + unit);
  upload(wo, n, 1, false);
  glUniform1i(glGetUniformLocation(prog, "bf_run_wo"), unit++);

  GLuint vao = 0;
  glGenVertexArrays(1, &vao);
  glBindVertexArray(vao);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  std::vector<float> out(size_t(n) * 4);
  glReadPixels(0, 0, n, 1, GL_RGBA, GL_FLOAT, out.data());
  if (glGetError() != GL_NO_ERROR) throw std::runtime_error("GL: error while drawing or reading back");

  std::ofstream o(argv[3]);
  char buf[128];
  for (int k = 0; k < n; ++k) {
    std::snprintf(buf, sizeof buf, "%.9g %.9g %.9g\n", out[4 * k], out[4 * k + 1], out[4 * k + 2]);
    o << buf;
  }
  if (!o) throw std::runtime_error(std::string(argv[3]) + ": write failed");
  eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(dpy, ctx);
  eglTerminate(dpy);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "bf_glsl_run: " << e.what() << "\n";
    return 1;
  }
}
