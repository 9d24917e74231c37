// Compiles generated GLSL (a brdf_factor_eval function) into a fragment
// shader for every target the exports promise (docs/design.md §5.7): OpenGL 3.3
// core, OpenGL 4.5, OpenGL ES 3.0 and Vulkan (glslangValidator -V), each with
// and without `extra_define`. Returns "" when all compile, else the failing
// target's glslangValidator output, or a message when glslangValidator is
// missing (scripts/install-deps.sh installs glslang-tools): a missing
// compiler fails the test instead of skipping it.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace bf_test {

inline std::string compile_glsl_all_targets(const std::string& glsl, const std::filesystem::path& dir,
                                            const std::string& extra_define = "") {
  if (std::system("command -v glslangValidator > /dev/null 2>&1") != 0)
    return "glslangValidator not found: scripts/install-deps.sh installs glslang-tools";
  struct Target {
    const char* version;
    const char* flags;
  };
  const Target targets[] = {{"#version 330 core\n", ""},
                            {"#version 450\n", ""},
                            {"#version 300 es\n", ""},
                            {"#version 450\n", "-V"}};
  const char* main_src =
      "\n#ifdef VULKAN\nlayout(location = 0) in vec3 v_wi;\nlayout(location = 1) in vec3 v_wo;\n"
      "#else\nin vec3 v_wi;\nin vec3 v_wo;\n#endif\n"
      "layout(location = 0) out vec4 color;\n"
      "void main() {\n  color = vec4(brdf_factor_eval(normalize(v_wi), normalize(v_wo)), 1.0);\n}\n";
  for (const Target& t : targets)
    for (const std::string& define : {std::string(), extra_define}) {
      const std::string shader = std::string(t.version) + define + glsl + main_src;
      const std::filesystem::path frag = dir / "test.frag", log = dir / "glslang.log",
                                  spv = dir / "test.spv";
      std::ofstream(frag) << shader;
      const std::string cmd = "glslangValidator " + std::string(t.flags) +
                              (std::string(t.flags).empty() ? "" : " -o " + spv.string()) + " " +
                              frag.string() + " > " + log.string() + " 2>&1";
      if (std::system(cmd.c_str()) != 0) {
        std::ifstream in(log);
        std::stringstream ss;
        ss << in.rdbuf();
        return std::string(t.version) + " " + t.flags + " " + define + ": " + ss.str();
      }
      if (extra_define.empty()) break;
    }
  return "";
}

}  // namespace bf_test
