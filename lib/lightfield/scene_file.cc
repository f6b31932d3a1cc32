// Scene files through Assimp, read in a child process (docs/method.md §4.4).
//
// Assimp reads some 40 formats, and hostile or broken files make Debian's Assimp 5.2 abort
// inside its post-processing or loop forever in its PLY reader (both found by fuzz_mesh_ply).
// Neither can be fixed here, so the import runs in a forked child that sends the flattened
// triangles back through a pipe: a crash of the importer becomes an error naming the file, a
// hang ends at the time limit, and Ctrl-C (StopRequested) ends the wait. What comes back is
// checked again in this process (sizes, finite values) before it becomes a Mesh.
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "core/input_file.h"
#include "core/stop_signal.h"
#include "lib/lightfield/scene_texture.h"
#include "lib/lightfield/scenes.h"

namespace lumislab {
namespace {

using V = Eigen::Vector3f;

// Flattened triangles: position, normal and albedo of each corner, 9 floats.
constexpr size_t kFloatsPerCorner = 9;

// The import itself (in the child): Assimp, then the checks of every face and vertex.
Mesh ImportWithAssimp(const std::string& path) {
  Assimp::Importer importer;
  const aiScene* scene =
      // ValidateDataStructure runs before the other steps: they index vertices by the file's
      // face indices, and a PLY face naming a vertex it lacks crashed them.
      importer.ReadFile(path, aiProcess_ValidateDataStructure | aiProcess_Triangulate |
                                  aiProcess_GenSmoothNormals | aiProcess_PreTransformVertices |
                                  aiProcess_JoinIdenticalVertices);
  if (!scene || !scene->mRootNode) {
    throw BadInput(path + ": cannot read scene (" + importer.GetErrorString() + ")");
  }
  Mesh m;
  for (unsigned k = 0; k < scene->mNumMeshes; ++k) {
    const aiMesh* mesh = scene->mMeshes[k];
    if (mesh == nullptr || mesh->mVertices == nullptr || mesh->mNormals == nullptr) continue;
    V colour(0.7f, 0.7f, 0.7f);
    aiColor4D diffuse;
    if (mesh->mMaterialIndex < scene->mNumMaterials &&
        scene->mMaterials[mesh->mMaterialIndex]->Get(AI_MATKEY_COLOR_DIFFUSE, diffuse) ==
            AI_SUCCESS &&
        std::isfinite(diffuse.r) && std::isfinite(diffuse.g) && std::isfinite(diffuse.b)) {
      colour = V(diffuse.r, diffuse.g, diffuse.b);
    }
    // A diffuse texture multiplies the colour (as OBJ's map_Kd and glTF's base colour do),
    // sampled at each corner's texture coordinate.
    DiffuseTexture texture;
    if (mesh->mMaterialIndex < scene->mNumMaterials && mesh->mTextureCoords[0] != nullptr)
      texture = LoadDiffuseTexture(*scene, *scene->mMaterials[mesh->mMaterialIndex], path);
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;
      // A file's face may name a vertex it does not have (a hostile PLY did): refuse it.
      for (unsigned c = 0; c < 3; ++c)
        if (face.mIndices[c] >= mesh->mNumVertices)
          throw InputError(path, "mesh " + std::to_string(k) + " face " + std::to_string(f),
                           "vertex indices below " + std::to_string(mesh->mNumVertices),
                           std::to_string(face.mIndices[c]));
      for (unsigned c = 0; c < 3; ++c) {
        const aiVector3D& p = mesh->mVertices[face.mIndices[c]];
        const aiVector3D n = mesh->mNormals[face.mIndices[c]];
        if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)))
          throw InputError(
              path, "mesh " + std::to_string(k) + " vertex " + std::to_string(face.mIndices[c]),
              "finite coordinates", "NaN or Inf");
        m.positions.emplace_back(p.x, p.y, p.z);
        m.normals.emplace_back(n.x, n.y, n.z);
        if (texture.empty()) {
          m.albedo.push_back(colour);
        } else {
          const aiVector3D& uv = mesh->mTextureCoords[0][face.mIndices[c]];
          m.albedo.push_back(colour.cwiseProduct(texture.Sample(uv.x, uv.y)));
        }
      }
    }
  }
  if (m.triangles() > kMaxSceneTriangles)
    throw InputError(path, "triangles", "at most " + std::to_string(kMaxSceneTriangles),
                     std::to_string(m.triangles()));
  if (m.positions.empty()) throw BadInput(path + ": the scene has no triangles");
  return m;
}

// PLY files are checked here before Assimp sees them: Assimp 5.2's PLY reader loops forever on
// a file cut short (even a header without "end_header"), which is what a half-copied file is.
// The header must be complete and well formed, and the body at least as long as its elements
// need: for binary files the fixed-size bytes of every element (a list at least its count),
// for ASCII files one non-empty line per element.
int PlyTypeSize(const std::string& type) {
  static const std::pair<const char*, int> kTypes[] = {
      {"char", 1},  {"uchar", 1},   {"int8", 1},   {"uint8", 1},  {"short", 2}, {"ushort", 2},
      {"int16", 2}, {"uint16", 2},  {"int", 4},    {"uint", 4},   {"int32", 4}, {"uint32", 4},
      {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
  for (const auto& [name, size] : kTypes)
    if (type == name) return size;
  return 0;
}

void CheckPlyFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  if (!std::getline(in, line) || (line != "ply" && line != "ply\r")) return;  // Assimp decides
  auto fail = [&](const std::string& field, const std::string& expected, const std::string& got) {
    throw InputError(path, field, expected, got);
  };
  constexpr uint64_t kMaxElementCount = 3 * kMaxSceneTriangles;
  std::string format;
  uint64_t min_body = 0;  // bytes the binary body needs at least
  uint64_t records = 0;   // records of all elements (lines of an ASCII body)
  uint64_t count = 0;     // records of the current element
  bool in_element = false, vertex = false, ended = false;
  for (int number = 2; !ended && std::getline(in, line); ++number) {
    if (in.tellg() > (1 << 20)) fail("header", "a header of at most 1 MiB", "more");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    const std::string field = "header line " + std::to_string(number);
    const std::string got = line.substr(0, 60);
    if (keyword == "format") {
      words >> format;
      if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
        fail(field, "format ascii, binary_little_endian or binary_big_endian", got);
    } else if (keyword == "element") {
      std::string name;
      int64_t n = -1;
      words >> name >> n;
      if (!words || n < 0 || uint64_t(n) > kMaxElementCount)
        fail(field, "element <name> <count in [0, " + std::to_string(kMaxElementCount) + "]>", got);
      count = uint64_t(n);
      records += count;
      in_element = true;
      vertex = vertex || name == "vertex";
    } else if (keyword == "property") {
      std::string type, count_type, item_type, name;
      words >> type;
      int size = PlyTypeSize(type);
      if (type == "list") {
        words >> count_type >> item_type;
        size = PlyTypeSize(item_type) > 0 ? PlyTypeSize(count_type) : 0;
      }
      words >> name;
      if (size == 0 || !words) fail(field, "property <PLY type> <name>", got);
      if (!in_element) fail(field, "a property after an element line", got);
      min_body += count * uint64_t(size);
    } else if (keyword == "end_header") {
      ended = true;
    } else if (keyword != "comment" && keyword != "obj_info" && !keyword.empty()) {
      fail(field, "format, element, property, comment, obj_info or end_header", got);
    }
  }
  if (!ended) fail("header", "a header that ends with end_header", "a file cut short");
  if (format.empty()) fail("header", "a format line", "nothing (missing)");
  if (!vertex) fail("header", "a vertex element", "nothing (missing)");
  const std::streamoff header_end = in.tellg();
  in.seekg(0, std::ios::end);
  const uint64_t body = uint64_t(in.tellg() - header_end);
  if (format != "ascii") {
    if (body < min_body)
      fail("body", "at least " + std::to_string(min_body) + " bytes for the header's elements",
           std::to_string(body) + " bytes (cut short?)");
    return;
  }
  in.seekg(header_end);
  uint64_t lines = 0;
  while (lines < records && std::getline(in, line))
    lines += line.find_first_not_of(" \t\r") != std::string::npos;
  if (lines < records)
    fail("body", std::to_string(records) + " non-empty lines for the header's elements",
         std::to_string(lines) + " (cut short?)");
}

bool WriteAll(int fd, const void* data, size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    size -= size_t(n);
  }
  return true;
}

// The child's message: a status byte (0: the mesh follows; otherwise the exit code of the error,
// whose text follows), then a 64-bit count and the floats or the text's bytes.
void RunChild(int fd, const std::string& path) {
  uint8_t status = 0;
  std::vector<float> floats;
  std::string text;
  try {
    const Mesh m = ImportWithAssimp(path);
    floats.reserve(m.positions.size() * kFloatsPerCorner);
    for (size_t k = 0; k < m.positions.size(); ++k)
      for (const V* v : {&m.positions[k], &m.normals[k], &m.albedo[k]})
        floats.insert(floats.end(), v->data(), v->data() + 3);
  } catch (const Error& e) {
    status = uint8_t(e.exit_code());
    text = e.what();
  } catch (const std::exception& e) {
    status = uint8_t(ExitCode::kBadInput);
    text = path + ": cannot read scene (" + e.what() + ")";
  }
  const uint64_t count = status == 0 ? floats.size() : text.size();
  const bool ok = WriteAll(fd, &status, 1) && WriteAll(fd, &count, sizeof count) &&
                  (status == 0 ? WriteAll(fd, floats.data(), floats.size() * sizeof(float))
                               : WriteAll(fd, text.data(), text.size()));
  _exit(ok ? 0 : 1);  // no atexit handlers or destructors of the parent's state
}

// Reads the child's message with a deadline, polling in 100 ms slices so that a stop request
// or the deadline ends the wait. Throws with the file named.
class ChildReader {
 public:
  ChildReader(int fd, std::string path, double timeout_s)
      : fd_(fd),
        path_(std::move(path)),
        timeout_s_(timeout_s),
        deadline_(std::chrono::steady_clock::now() +
                  std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                      std::chrono::duration<double>(timeout_s))) {}

  // Fills `size` bytes; false when the child closed the pipe first (it crashed or was killed).
  bool Read(void* data, size_t size) {
    char* p = static_cast<char*>(data);
    while (size > 0) {
      if (StopRequested()) throw Failure(path_ + ": stopped while reading the scene");
      if (std::chrono::steady_clock::now() > deadline_)
        throw BadInput(path_ + ": reading the scene took longer than " +
                       std::to_string(int(timeout_s_)) + " s (the importer may loop on it)");
      pollfd pfd{fd_, POLLIN, 0};
      const int ready = poll(&pfd, 1, 100);
      if (ready < 0 && errno != EINTR) throw IoError(path_, std::strerror(errno));
      if (ready <= 0) continue;
      const ssize_t n = read(fd_, p, size);
      if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
      if (n < 0) throw IoError(path_, std::strerror(errno));
      if (n == 0) return false;
      p += n;
      size -= size_t(n);
    }
    return true;
  }

 private:
  int fd_;
  std::string path_;
  double timeout_s_;
  std::chrono::steady_clock::time_point deadline_;
};

// The child's process and pipe: killed and reaped however the parent leaves.
struct Child {
  pid_t pid = -1;
  int fd = -1;
  int status = 0;
  bool reaped = false;
  ~Child() {
    if (fd >= 0) close(fd);
    if (pid > 0 && !reaped) {
      kill(pid, SIGKILL);
      while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
    }
  }
  void Reap() {
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    reaped = true;
  }
};

Mesh ReceiveMesh(Child& child, const std::string& path, double timeout_s) {
  ChildReader reader(child.fd, path, timeout_s);
  uint8_t status = 0;
  uint64_t count = 0;
  const bool got = reader.Read(&status, 1) && reader.Read(&count, sizeof count);
  if (got && status != 0) {
    if (count > (1u << 20)) throw Failure(path + ": the scene importer sent a malformed reply");
    std::string text(count, '\0');
    if (!reader.Read(text.data(), text.size()))
      throw Failure(path + ": the scene importer sent a malformed reply");
    throw Error(status == 3   ? ExitCode::kIoError
                : status == 2 ? ExitCode::kBadInput
                              : ExitCode::kFailure,
                text);
  }
  if (got && count % (3 * kFloatsPerCorner) == 0 &&
      count / (3 * kFloatsPerCorner) <= kMaxSceneTriangles) {
    std::vector<float> floats(count);
    if (reader.Read(floats.data(), floats.size() * sizeof(float))) {
      Mesh m;
      for (size_t k = 0; k < count; k += kFloatsPerCorner) {
        m.positions.emplace_back(floats[k], floats[k + 1], floats[k + 2]);
        m.normals.emplace_back(floats[k + 3], floats[k + 4], floats[k + 5]);
        m.albedo.emplace_back(floats[k + 6], floats[k + 7], floats[k + 8]);
        if (!m.positions.back().allFinite())
          throw InputError(path, "vertex " + std::to_string(k / kFloatsPerCorner),
                           "finite coordinates", "NaN or Inf");
      }
      if (m.positions.empty()) throw BadInput(path + ": the scene has no triangles");
      return m;
    }
  }
  // The pipe closed early: the importer died.
  child.Reap();
  const std::string how = WIFSIGNALED(child.status)
                              ? "signal " + std::to_string(WTERMSIG(child.status)) + " (" +
                                    strsignal(WTERMSIG(child.status)) + ")"
                              : "exit " + std::to_string(WEXITSTATUS(child.status));
  throw BadInput(path + ": cannot read scene (the importer, Assimp, failed on it: " + how + ")");
}

}  // namespace

Mesh LoadSceneFile(const std::string& path, double timeout_s) {
  CheckInputFile(path, "scene file");
  CheckPlyFile(path);
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) throw IoError(path, std::string("pipe: ") + std::strerror(errno));
  Child child;
  child.pid = fork();
  if (child.pid == 0) {
    close(fds[0]);
    signal(SIGINT, SIG_IGN);  // the parent decides when to stop; it kills the child then
    signal(SIGTERM, SIG_DFL);
    RunChild(fds[1], path);
  }
  close(fds[1]);
  child.fd = fds[0];
  if (child.pid < 0) throw IoError(path, std::string("fork: ") + std::strerror(errno));
  Mesh m = ReceiveMesh(child, path, timeout_s);
  child.Reap();
  return m;
}

}  // namespace lumislab
