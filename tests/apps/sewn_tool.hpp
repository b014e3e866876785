// The sewn binary run from a test, on scenes and Gmsh files written to the scratch folder: what
// the user of the tool reads (exit code, messages) checked as they read it.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "scratch.hpp"

namespace sewn::test::tool {

inline std::filesystem::path tool_scratch(const std::string& name) { return sewn::test::scratch("tool/" + name); }

inline std::filesystem::path tool_write(const std::string& name, const std::string& text) {
  const std::filesystem::path p = tool_scratch(name);
  std::ofstream(p) << text;
  return p;
}

inline std::string read(const std::filesystem::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Runs `sewn <args>` through bash (for ulimit), with `prefix` run first; returns the exit code
// and fills `err` with what it printed (standard output and error).
inline int run_sewn(const std::string& args, std::string& err, const std::string& prefix = "") {
  const std::filesystem::path log = tool_scratch("stderr.txt");
  const std::string inner = prefix + std::string(SEWN_BINARY) + " " + args + " > " + log.string() + " 2>&1";
  const std::string cmd = "bash -c '" + inner + "'";
  const int status = std::system(cmd.c_str());
  err = read(log);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// A Gmsh 2.2 file of the given nodes ("tag x y z") and elements ("tag type tags... nodes").
inline std::string msh(const std::vector<std::string>& nodes, const std::vector<std::string>& elements) {
  std::string s = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n" + std::to_string(nodes.size()) + "\n";
  for (const auto& n : nodes) s += n + "\n";
  s += "$EndNodes\n$Elements\n" + std::to_string(elements.size()) + "\n";
  for (const auto& e : elements) s += e + "\n";
  return s + "$EndElements\n";
}

// The unit cube's 8 points (tags 1..8) and the given elements ("type tags... nodes"), tagged 1..n.
inline std::string cube_msh(const std::vector<std::string>& elements) {
  const char* corners[] = {"0 0 0", "1 0 0", "1 1 0", "0 1 0", "0 0 1", "1 0 1", "1 1 1", "0 1 1"};
  std::vector<std::string> nodes, numbered;
  for (int i = 0; i < 8; ++i) nodes.push_back(std::to_string(i + 1) + " " + corners[i]);
  for (std::size_t i = 0; i < elements.size(); ++i) numbered.push_back(std::to_string(i + 1) + " " + elements[i]);
  return msh(nodes, numbered);
}

// A scene of `meshes` (JSON objects) with model.type `model` and model.groups `groups` (a JSON
// list); `more` (JSON members, each with a trailing comma) goes before its last key.
inline std::string file_scene(const std::string& model, const std::vector<std::string>& meshes, const std::string& groups = "[]",
                              const std::string& more = "") {
  std::string list;
  for (const auto& m : meshes) list += (list.empty() ? "" : ", ") + m;
  return R"({"materials": {"m": {"young": 1e6, "density": 1000}}, "model": {"type": ")" + model + R"(", "groups": )" + groups + R"(},
      "meshes": [)" + list + "], " + more + R"("duration": 0.01})";
}

inline std::string file_mesh(const std::filesystem::path& p, const std::string& material = "m") {
  return R"({"type": "file", "path": ")" + p.string() + R"(", "material": ")" + material + R"("})";
}

}  // namespace sewn::test::tool
