#include "measure/closed_meshes.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <numeric>
#include <tuple>

#include "scene/load.h"

namespace raypack {
namespace {

using VertexKey = std::tuple<float, float, float>;
VertexKey key_of(const Vec3f& v) { return {v.x, v.y, v.z}; }

/// Union-find with path halving.
struct DisjointSets {
    std::vector<std::uint32_t> parent;
    explicit DisjointSets(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
    std::uint32_t find(std::uint32_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    }
    void join(std::uint32_t a, std::uint32_t b) { parent[find(a)] = find(b); }
};

}  // namespace

void add_uv_sphere_mesh(Scene& scene, const Vec3f& centre, float radius, int segments, int rings,
                        std::uint32_t material) {
    // Ring r = 0 and r = rings are the poles: one vertex each.
    std::vector<Vec3f> ring_vertex(std::size_t((rings - 1) * segments));
    for (int r = 1; r < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            const double theta = std::numbers::pi * r / rings, phi = 2 * std::numbers::pi * s / segments;
            const Vec3f unit{float(std::sin(theta) * std::cos(phi)), float(std::cos(theta)),
                             float(std::sin(theta) * std::sin(phi))};
            ring_vertex[std::size_t((r - 1) * segments + s)] = centre + unit * radius;
        }
    const Vec3f north = centre + Vec3f{0, radius, 0}, south = centre - Vec3f{0, radius, 0};
    auto vertex = [&](int r, int s) {
        if (r == 0) return north;
        if (r == rings) return south;
        return ring_vertex[std::size_t((r - 1) * segments + s % segments)];
    };
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            if (r > 0) scene.add_triangle(vertex(r, s), vertex(r, s + 1), vertex(r + 1, s), material);
            if (r < rings - 1) scene.add_triangle(vertex(r, s + 1), vertex(r + 1, s + 1), vertex(r + 1, s), material);
        }
}

ObjectScene group_into_objects(Scene scene) {
    const std::size_t n = scene.primitive_count();
    DisjointSets sets(n);
    // Edges (sorted vertex pairs) to the first triangle that has them.
    std::map<std::pair<VertexKey, VertexKey>, std::uint32_t> edge_owner;
    for (std::uint32_t prim = 0; prim < n; ++prim) {
        const PrimRef ref = scene.prims[prim];
        if (ref.kind != PrimKind::Triangle) continue;
        const VertexKey v[3] = {key_of(scene.triangles.p0[ref.index]), key_of(scene.triangles.p1[ref.index]),
                                key_of(scene.triangles.p2[ref.index])};
        for (int e = 0; e < 3; ++e) {
            auto edge = std::minmax(v[e], v[(e + 1) % 3]);
            const auto [it, inserted] = edge_owner.try_emplace({edge.first, edge.second}, prim);
            if (!inserted) sets.join(prim, it->second);
        }
    }
    ObjectScene out;
    std::map<std::uint32_t, std::uint32_t> object_of_root;
    out.object.resize(n);
    for (std::uint32_t prim = 0; prim < n; ++prim) {
        const auto [it, inserted] = object_of_root.try_emplace(sets.find(prim), std::uint32_t(object_of_root.size()));
        out.object[prim] = it->second;
    }
    // Centroids: spheres their centres, meshes the mean of distinct vertices.
    std::vector<std::map<VertexKey, Vec3f>> vertices(object_of_root.size());
    out.centroid.assign(object_of_root.size(), Vec3f{});
    for (std::uint32_t prim = 0; prim < n; ++prim) {
        const PrimRef ref = scene.prims[prim];
        if (ref.kind == PrimKind::Sphere) out.centroid[out.object[prim]] = scene.spheres.center[ref.index];
        if (ref.kind != PrimKind::Triangle) continue;
        for (const Vec3f& p : {scene.triangles.p0[ref.index], scene.triangles.p1[ref.index], scene.triangles.p2[ref.index]})
            vertices[out.object[prim]].emplace(key_of(p), p);
    }
    for (std::size_t o = 0; o < vertices.size(); ++o) {
        if (vertices[o].empty()) continue;
        Vec3d sum{0, 0, 0};
        for (const auto& [k, p] : vertices[o]) sum = sum + Vec3d(p);
        const double count = double(vertices[o].size());
        out.centroid[o] = Vec3f{float(sum.x / count), float(sum.y / count), float(sum.z / count)};
    }
    out.scene = std::move(scene);
    return out;
}

ObjectScene leak_test_meshes(int detail, int tetra_size) {
    Scene scene = load_scene("gen:tetra:" + std::to_string(tetra_size));
    if (scene.materials.empty()) scene.materials.push_back(Material{});
    const std::uint32_t material = 0;
    add_uv_sphere_mesh(scene, {3, 0, 0}, 0.7f, 8, 6, material);
    add_uv_sphere_mesh(scene, {-3, 0, 0}, 0.9f, 32, 16, material);
    // Far from the origin, vertices are coarse: edges no longer meet on a
    // straight line in float, which is where Moeller-Trumbore cracks.
    add_uv_sphere_mesh(scene, {1000, 2000, -500}, 1.3f, 32, 16, material);
    if (detail > 0) {
        add_uv_sphere_mesh(scene, {0, 3, 0}, 1.1f, 128, 64, material);
        add_uv_sphere_mesh(scene, {0, -3, 0}, 1.0f, 512, 256, material);
    }
    scene.update_features();
    return group_into_objects(std::move(scene));
}

ObjectScene mixed_convex_scene(float scale, const Vec3f& translation) {
    Scene scene;
    Material shiny;
    shiny.kd = 0.7f, shiny.ks = 0.3f, shiny.shine = 20;
    scene.materials.push_back(shiny);
    auto at = [&](float x, float y, float z) { return translation + Vec3f{x, y, z} * scale; };
    add_uv_sphere_mesh(scene, at(0, 0, 0), scale, 24, 12, 0);
    add_uv_sphere_mesh(scene, at(-2.6f, 0.1f, -1.5f), 0.9f * scale, 64, 32, 0);
    scene.add_sphere(at(2.5f, 0, 0), 0.8f * scale, 0);
    scene.add_sphere(at(-2.4f, -0.6f, 1.4f), 0.5f * scale, 0);
    // A regular tetrahedron resting on the floor.
    const Vec3f a = at(1.2f, -1.1f, 2.2f), b = at(2.4f, -1.1f, 2.2f), c = at(1.8f, -1.1f, 3.2f), d = at(1.8f, 0, 2.55f);
    scene.add_triangle(a, c, b, 0);
    scene.add_triangle(a, b, d, 0);
    scene.add_triangle(b, c, d, 0);
    scene.add_triangle(c, a, d, 0);
    scene.add_triangle(at(-6, -1.2f, -6), at(6, -1.2f, -6), at(6, -1.2f, 6), 0);
    scene.add_triangle(at(-6, -1.2f, -6), at(6, -1.2f, 6), at(-6, -1.2f, 6), 0);
    scene.lights.push_back(PointLight{at(3, 8, 6)});
    scene.camera.from = at(0, 2.5f, 9);
    scene.camera.at = at(0, -0.3f, 0);
    scene.camera.fov_deg = 50;
    scene.has_camera = true;
    scene.update_features();
    ObjectScene out = group_into_objects(std::move(scene));
    // The floor (the last object) is open: its inner side is below it.
    out.centroid[out.object.back()] = at(0, -50, 0);
    return out;
}

}  // namespace raypack
