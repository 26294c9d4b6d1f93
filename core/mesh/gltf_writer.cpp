#include "core/mesh/gltf_writer.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <limits>
#include <sstream>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/atomic_file.h"
#include "core/mesh/corner_normals.h"
#include "core/mesh/element_kinds.h"

namespace mq {
namespace {

constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

// Appends the bytes of v to the buffer, 4-byte aligned as glTF requires of accessors.
template <typename T>
size_t append_bytes(std::vector<unsigned char>& data, const std::vector<T>& v) {
  while (data.size() % 4) data.push_back(0);
  const size_t offset = data.size();
  data.resize(offset + v.size() * sizeof(T));
  if (!v.empty()) std::memcpy(data.data() + offset, v.data(), v.size() * sizeof(T));
  return offset;
}

int add_view(tinygltf::Model& model, size_t offset, size_t length, int target) {
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = offset;
  view.byteLength = length;
  view.target = target;
  model.bufferViews.push_back(view);
  return static_cast<int>(model.bufferViews.size()) - 1;
}

int add_accessor(tinygltf::Model& model, int view, size_t offset, int component, int type,
                 size_t count) {
  tinygltf::Accessor a;
  a.bufferView = view;
  a.byteOffset = offset;
  a.componentType = component;
  a.type = type;
  a.count = count;
  model.accessors.push_back(a);
  return static_cast<int>(model.accessors.size()) - 1;
}

}  // namespace

void write_glb(const std::string& path, const TriMesh& mesh, const WriteOptions& options) {
  const ElementLabels labels = element_labels(mesh);
  MQ_CHECK(labels.count <= (1 << 24), InvalidInput, path, ": ", labels.count,
           " elements are more than a glTF float attribute numbers exactly (2^24)");
  const CornerNormals corners = corner_normals(mesh.V, mesh.F, options.crease_degrees);
  // One glTF vertex per (vertex, corner normal) pair, numbered in order of first use.
  const Eigen::Index nf = mesh.F.rows();
  std::vector<int> of_normal(static_cast<size_t>(corners.N.rows()), -1);
  std::vector<int> gl_vertex, gl_normal;  // the mesh vertex and corner normal of each
  std::vector<unsigned> corner_index(static_cast<size_t>(3 * nf));
  for (Eigen::Index f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      const int n = corners.FN(f, k);  // distinct per vertex, so n names the pair
      int& slot = of_normal[static_cast<size_t>(n)];
      if (slot < 0) {
        slot = static_cast<int>(gl_vertex.size());
        gl_vertex.push_back(mesh.F(f, k));
        gl_normal.push_back(n);
      }
      corner_index[static_cast<size_t>(3 * f + k)] = static_cast<unsigned>(slot);
    }
  const size_t nv = gl_vertex.size();
  std::vector<float> position(3 * nv), normal(3 * nv), element(nv);
  std::vector<double> lo(3, std::numeric_limits<double>::infinity()), hi(3, -lo[0]);
  for (size_t i = 0; i < nv; ++i) {
    for (int k = 0; k < 3; ++k) {
      const float p = static_cast<float>(mesh.V(gl_vertex[i], k));
      position[3 * i + k] = p;
      normal[3 * i + k] = static_cast<float>(corners.N(gl_normal[i], k));
      lo[k] = std::min(lo[k], static_cast<double>(p));
      hi[k] = std::max(hi[k], static_cast<double>(p));
    }
    element[i] = static_cast<float>(labels.vertex_element[static_cast<size_t>(gl_vertex[i])]);
  }

  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "meshquilt";
  model.buffers.resize(1);
  std::vector<unsigned char>& data = model.buffers[0].data;
  const size_t pos_at = append_bytes(data, position);
  const size_t nrm_at = append_bytes(data, normal);
  const size_t id_at = append_bytes(data, element);
  // Indices grouped by kind, faces in order within a kind.
  std::vector<std::vector<unsigned>> by_kind(labels.kinds.size());
  for (Eigen::Index f = 0; f < nf; ++f) {
    const int kind =
        labels.element_kind[static_cast<size_t>(labels.face_element[static_cast<size_t>(f)])];
    for (int k = 0; k < 3; ++k)
      by_kind[static_cast<size_t>(kind)].push_back(corner_index[static_cast<size_t>(3 * f + k)]);
  }
  std::vector<unsigned> indices;
  std::vector<size_t> kind_at;
  for (const auto& list : by_kind) {
    kind_at.push_back(indices.size() * sizeof(unsigned));
    indices.insert(indices.end(), list.begin(), list.end());
  }
  const size_t idx_at = append_bytes(data, indices);
  while (data.size() % 4) data.push_back(0);

  const int pos_view = add_view(model, pos_at, position.size() * sizeof(float), kArrayBuffer);
  const int nrm_view = add_view(model, nrm_at, normal.size() * sizeof(float), kArrayBuffer);
  const int id_view = add_view(model, id_at, element.size() * sizeof(float), kArrayBuffer);
  const int idx_view =
      add_view(model, idx_at, indices.size() * sizeof(unsigned), kElementArrayBuffer);
  const int pos =
      add_accessor(model, pos_view, 0, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, nv);
  model.accessors[static_cast<size_t>(pos)].minValues = lo;
  model.accessors[static_cast<size_t>(pos)].maxValues = hi;
  const int nrm =
      add_accessor(model, nrm_view, 0, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, nv);
  const int ids =
      add_accessor(model, id_view, 0, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR, nv);

  tinygltf::Mesh gm;
  gm.name = std::filesystem::path(path).stem().string();
  const std::vector<std::string> names = unique_kind_names(labels.kinds);
  for (size_t k = 0; k < by_kind.size(); ++k) {
    if (by_kind[k].empty()) continue;
    const std::string& name = names[k];
    const KindMaterial look = kind_material(name);
    tinygltf::Material m;
    m.name = name;
    m.pbrMetallicRoughness.baseColorFactor = {look.r, look.g, look.b, 1.0};
    m.pbrMetallicRoughness.metallicFactor = look.metallic;
    m.pbrMetallicRoughness.roughnessFactor = look.roughness;
    model.materials.push_back(m);
    tinygltf::Primitive p;
    p.mode = TINYGLTF_MODE_TRIANGLES;
    p.material = static_cast<int>(model.materials.size()) - 1;
    p.attributes["POSITION"] = pos;
    p.attributes["NORMAL"] = nrm;
    p.attributes["_ELEMENT_ID"] = ids;
    p.indices = add_accessor(model, idx_view, kind_at[k], TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                             TINYGLTF_TYPE_SCALAR, by_kind[k].size());
    gm.primitives.push_back(p);
  }
  model.meshes.push_back(gm);
  tinygltf::Node node;
  node.mesh = 0;
  node.name = gm.name;
  model.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes.push_back(0);
  model.scenes.push_back(scene);
  model.defaultScene = 0;

  std::ostringstream stream;
  tinygltf::TinyGLTF writer;
  MQ_CHECK(writer.WriteGltfSceneToStream(&model, stream, false, true), Error, path,
           ": the glTF writer failed");
  AtomicOutputFile out(path);
  out.append(stream.str());
  commit_with(out, options.companion_path, options.companion_bytes);
}

}  // namespace mq
