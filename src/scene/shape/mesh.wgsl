// A mesh triangle's shading data in input order (GpuMeshTri in render/gpu/layout.rs): edges for
// the geometric normal, the id of its mesh object, and the mesh's albedo. Where a ray meets the
// triangles is the acceleration structure's business (src/accel).

struct MeshTri {
    e1: vec3<f32>,
    object: u32,
    e2: vec3<f32>,
    albedo: f32,
}
