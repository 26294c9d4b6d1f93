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

// One glTF vertex per (vertex, corner normal) pair, numbered in order of first use: the mesh
// vertex and corner normal of each, and each corner's glTF vertex (#F by 3, row-major).
struct GlVertices {
  std::vector<int> vertex, normal;
  std::vector<unsigned> corner;
};

GlVertices gl_vertices(const MatrixX3i& F, const CornerNormals& corners) {
  const Eigen::Index nf = F.rows();
  GlVertices gl;
  std::vector<int> of_normal(static_cast<size_t>(corners.N.rows()), -1);
  gl.corner.resize(static_cast<size_t>(3 * nf));
  for (Eigen::Index f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      const int n = corners.FN(f, k);  // distinct per vertex, so n names the pair
      int& slot = of_normal[static_cast<size_t>(n)];
      if (slot < 0) {
        slot = static_cast<int>(gl.vertex.size());
        gl.vertex.push_back(F(f, k));
        gl.normal.push_back(n);
      }
      gl.corner[static_cast<size_t>(3 * f + k)] = static_cast<unsigned>(slot);
    }
  return gl;
}

// The glTF vertices' float attributes (position, normal, element id) and the positions' bounds.
struct GlAttributes {
  std::vector<float> position, normal, element;
  std::vector<double> lo, hi;
};

GlAttributes gl_attributes(const TriMesh& mesh, const CornerNormals& corners, const GlVertices& gl,
                           const ElementLabels& labels) {
  const size_t nv = gl.vertex.size();
  GlAttributes a;
  a.position.resize(3 * nv);
  a.normal.resize(3 * nv);
  a.element.resize(nv);
  a.lo.assign(3, std::numeric_limits<double>::infinity());
  a.hi.assign(3, -a.lo[0]);
  for (size_t i = 0; i < nv; ++i) {
    for (int k = 0; k < 3; ++k) {
      const float p = static_cast<float>(mesh.V(gl.vertex[i], k));
      a.position[3 * i + k] = p;
      a.normal[3 * i + k] = static_cast<float>(corners.N(gl.normal[i], k));
      a.lo[k] = std::min(a.lo[k], static_cast<double>(p));
      a.hi[k] = std::max(a.hi[k], static_cast<double>(p));
    }
    a.element[i] = static_cast<float>(labels.vertex_element[static_cast<size_t>(gl.vertex[i])]);
  }
  return a;
}

// Corner indices grouped by kind, faces in order within a kind.
std::vector<std::vector<unsigned>> indices_by_kind(const ElementLabels& labels,
                                                   const GlVertices& gl, Eigen::Index nf) {
  std::vector<std::vector<unsigned>> by_kind(labels.kinds.size());
  for (Eigen::Index f = 0; f < nf; ++f) {
    const int kind =
        labels.element_kind[static_cast<size_t>(labels.face_element[static_cast<size_t>(f)])];
    for (int k = 0; k < 3; ++k)
      by_kind[static_cast<size_t>(kind)].push_back(gl.corner[static_cast<size_t>(3 * f + k)]);
  }
  return by_kind;
}

// One primitive and one PBR material per kind with faces, sharing the vertex accessors.
void add_kind_primitives(tinygltf::Model& model, tinygltf::Mesh& gm, const ElementLabels& labels,
                         const std::vector<std::vector<unsigned>>& by_kind,
                         const std::vector<size_t>& kind_at, int idx_view, int pos, int nrm,
                         int ids) {
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
}

// The mesh as the one node of the one scene.
void add_scene(tinygltf::Model& model, const tinygltf::Mesh& gm) {
  model.meshes.push_back(gm);
  tinygltf::Node node;
  node.mesh = 0;
  node.name = gm.name;
  model.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes.push_back(0);
  model.scenes.push_back(scene);
  model.defaultScene = 0;
}

}  // namespace

void write_glb(const std::string& path, const TriMesh& mesh, const WriteOptions& options) {
  const ElementLabels labels = element_labels(mesh);
  MQ_CHECK(labels.count <= (1 << 24), InvalidInput, path, ": ", labels.count,
           " elements are more than a glTF float attribute numbers exactly (2^24)");
  const CornerNormals corners = corner_normals(mesh.V, mesh.F, options.crease_degrees);
  const GlVertices gl = gl_vertices(mesh.F, corners);
  const size_t nv = gl.vertex.size();
  const GlAttributes a = gl_attributes(mesh, corners, gl, labels);

  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "meshquilt";
  model.buffers.resize(1);
  std::vector<unsigned char>& data = model.buffers[0].data;
  const size_t pos_at = append_bytes(data, a.position);
  const size_t nrm_at = append_bytes(data, a.normal);
  const size_t id_at = append_bytes(data, a.element);
  const std::vector<std::vector<unsigned>> by_kind = indices_by_kind(labels, gl, mesh.F.rows());
  std::vector<unsigned> indices;
  std::vector<size_t> kind_at;
  for (const auto& list : by_kind) {
    kind_at.push_back(indices.size() * sizeof(unsigned));
    indices.insert(indices.end(), list.begin(), list.end());
  }
  const size_t idx_at = append_bytes(data, indices);
  while (data.size() % 4) data.push_back(0);

  const int pos_view = add_view(model, pos_at, a.position.size() * sizeof(float), kArrayBuffer);
  const int nrm_view = add_view(model, nrm_at, a.normal.size() * sizeof(float), kArrayBuffer);
  const int id_view = add_view(model, id_at, a.element.size() * sizeof(float), kArrayBuffer);
  const int idx_view =
      add_view(model, idx_at, indices.size() * sizeof(unsigned), kElementArrayBuffer);
  const int pos =
      add_accessor(model, pos_view, 0, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, nv);
  model.accessors[static_cast<size_t>(pos)].minValues = a.lo;
  model.accessors[static_cast<size_t>(pos)].maxValues = a.hi;
  const int nrm =
      add_accessor(model, nrm_view, 0, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, nv);
  const int ids =
      add_accessor(model, id_view, 0, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR, nv);

  tinygltf::Mesh gm;
  gm.name = std::filesystem::path(path).stem().string();
  add_kind_primitives(model, gm, labels, by_kind, kind_at, idx_view, pos, nrm, ids);
  add_scene(model, gm);

  std::ostringstream stream;
  tinygltf::TinyGLTF writer;
  MQ_CHECK(writer.WriteGltfSceneToStream(&model, stream, false, true), Error, path,
           ": the glTF writer failed");
  AtomicOutputFile out(path);
  out.append(stream.str());
  commit_with(out, options.companion_path, options.companion_bytes);
}

}  // namespace mq
