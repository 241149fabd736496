#pragma once

#include <string>

#include "mesh/tri_mesh.h"

namespace orthoface::mesh {

struct MeshReadOptions {
  bool load_texture = true;  // OBJ map_Kd, PLY "comment TextureFile", glTF images
  std::string texture_path;  // when set, this image is the texture (overrides the file's);
                             // a relative path is taken from the mesh file's folder
  // glTF stores v = 0 at the TOP of the image and is flipped into TriMesh's bottom-origin v.
  // Files exported with OBJ-style UVs (e.g. three.js LeePerrySmith.glb) need this set.
  bool gltf_uv_bottom_origin = false;
};

// Reads a triangle mesh; the format comes from the extension (case-insensitive): .obj (v, vt,
// f with polygons fan-triangulated, vertices split where one position has several vt, optional
// "v x y z r g b" colours, mtllib/map_Kd texture), .ply (ascii / binary, colours, s t or u v
// texture coordinates, "comment TextureFile"), .off / .coff, .glb and .gltf (POSITION,
// TEXCOORD_0, indices of 8/16/32 bits, node transforms, embedded or external buffers/images).
// Positions are returned as stored (no unit change). Throws std::runtime_error naming the file
// and the problem: missing / unreadable, unknown extension, corrupt or truncated content,
// non-finite values, indices out of range, no faces, or only zero-area triangles.
TriMesh read_mesh(const std::string& path, const MeshReadOptions& options = {});

struct MeshWriteOptions {
  bool binary = true;  // PLY only: binary_little_endian, else ascii
};

// Writes .obj (+ <stem>.mtl and <stem>.png when the mesh has a texture and uvs), .ply (colours
// as uchar red/green/blue, uvs as float s t) or .off (COFF with colours). Every file is written
// to a temporary beside it (io::temp_path_for), and all are renamed together at the end
// (io::FileGroup), so a failure leaves no partial output and no texture without its mesh.
// Throws std::invalid_argument for an invalid mesh (check_mesh) and std::runtime_error for an
// unknown extension or IO error.
void write_mesh(const TriMesh& mesh, const std::string& path, const MeshWriteOptions& options = {});

}  // namespace orthoface::mesh
