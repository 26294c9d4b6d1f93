// Running the meshquilt executable from the CLI tests: exit status, captured streams, files.
#pragma once

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/test_support.h"

namespace mq {

namespace fs = std::filesystem;

struct CliRun {
  int status = -1;  // exit code, or 128 + signal number when killed by a signal
  bool signaled = false;
  std::string out, err;
  std::vector<std::string> err_lines() const {
    std::vector<std::string> lines;
    std::istringstream in(err);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
  }
};

using test::slurp;
using test::spit;

// Runs `meshquilt ARGS` in `dir` with stdout and stderr captured in files (so neither is a
// terminal); with timeout_seconds > 0 under timeout(1), which kills it after that long (exit
// status 137).
inline CliRun meshquilt(const std::string& dir, const std::string& args,
                        double timeout_seconds = 0) {
  const std::string out = dir + "/.stdout", err = dir + "/.stderr";
  const std::string limit =
      timeout_seconds > 0 ? "timeout -s KILL " + std::to_string(timeout_seconds) + " " : "";
  const std::string cmd = "cd '" + dir + "' && exec " + limit + "'" + std::string(MESHQUILT_CLI) +
                          "' " + args + " >'" + out + "' 2>'" + err + "' </dev/null";
  const int raw = std::system(cmd.c_str());
  CliRun r;
  if (WIFEXITED(raw)) {
    r.status = WEXITSTATUS(raw);
  } else if (WIFSIGNALED(raw)) {
    r.signaled = true;
    r.status = 128 + WTERMSIG(raw);
  }
  r.out = slurp(out);
  r.err = slurp(err);
  fs::remove(out);
  fs::remove(err);
  return r;
}

// Files in dir (names), without the captured streams.
inline std::vector<std::string> listing(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// A mesh as a plain OBJ (positions at full precision, faces), for bases made in a test.
inline void write_obj(const std::string& path, const TriMesh& m) {
  std::ostringstream obj;
  obj.precision(17);
  for (int v = 0; v < m.num_vertices(); ++v)
    obj << "v " << m.V(v, 0) << " " << m.V(v, 1) << " " << m.V(v, 2) << "\n";
  for (int f = 0; f < m.num_faces(); ++f)
    obj << "f " << m.F(f, 0) + 1 << " " << m.F(f, 1) + 1 << " " << m.F(f, 2) + 1 << "\n";
  spit(path, obj.str());
}

// The value printed for "key": in a JSON text (the first occurrence), as text.
inline std::string json_value(const std::string& json, const std::string& key) {
  const std::string k = "\"" + key + "\":";
  const size_t at = json.find(k);
  if (at == std::string::npos) return "";
  size_t b = at + k.size();
  while (b < json.size() && json[b] == ' ') ++b;
  size_t e = b;
  while (e < json.size() && json[e] != ',' && json[e] != '\n' && json[e] != '}') ++e;
  return json.substr(b, e - b);
}

}  // namespace mq
