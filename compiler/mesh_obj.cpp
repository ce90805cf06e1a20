// mesh_obj.cpp — splat_obj_read (mesh.h): an OBJ file's triangles through
// tinyobjloader (Debian's libtinyobjloader, float build).
//
// C++ only because tinyobjloader is a C++ library.  Keep this file to this
// one function: reading the file (bounded, regular files only), checking
// its text against the limits, merging vertices, normals and uv are
// mesh.c's.  The text is parsed from memory, with no material reader, so
// an OBJ's `mtllib` never opens another file.
#include "mesh.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include <tiny_obj_loader.h>

extern "C" {
#include "util.h"   // xmalloc: the one out-of-memory policy
}

static bool fail(char **err, const std::string &msg)
{
    *err = strdup(msg.c_str());
    return false;
}

extern "C" bool splat_obj_parse(const char *bytes, size_t len, splat_obj_corners *c,
                                char **err)
{
    *c = splat_obj_corners{};
    *err = nullptr;
    std::stringstream text(std::string(bytes, len));

    tinyobj::attrib_t a;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warn, msg;
    if (!tinyobj::LoadObj(&a, &shapes, &materials, &warn, &msg, &text, nullptr, true)) {
        while (!msg.empty() && (msg.back() == '\n' || msg.back() == '.'))
            msg.pop_back();
        return fail(err, "not an OBJ file: " + (msg.empty() ? std::string("parse error") : msg));
    }

    size_t n = 0;
    for (const auto &s : shapes)
        n += s.mesh.indices.size();
    if (n == 0)
        return fail(err, "no triangles (an undergrowth mesh needs `f` faces)");
    if (n % 3 || n > UINT32_MAX / 4)
        return fail(err, "not a triangle list");
    std::vector<float> pos(3 * n), nrm(3 * n, 0.0f), uv(2 * n, NAN);
    size_t nv = a.vertices.size() / 3, nn = a.normals.size() / 3, nt = a.texcoords.size() / 2;
    size_t k = 0;
    for (const auto &s : shapes)
        for (const auto &ix : s.mesh.indices) {
            if (ix.vertex_index < 0 || (size_t)ix.vertex_index >= nv ||
                (ix.normal_index >= 0 && (size_t)ix.normal_index >= nn) ||
                (ix.texcoord_index >= 0 && (size_t)ix.texcoord_index >= nt))
                return fail(err, "a face refers to a vertex, normal or uv the file does not have");
            for (int j = 0; j < 3; j++) {
                pos[3 * k + j] = a.vertices[3 * (size_t)ix.vertex_index + j];
                if (ix.normal_index >= 0)
                    nrm[3 * k + j] = a.normals[3 * (size_t)ix.normal_index + j];
            }
            if (ix.texcoord_index >= 0)
                for (int j = 0; j < 2; j++)
                    uv[2 * k + j] = a.texcoords[2 * (size_t)ix.texcoord_index + j];
            k++;
        }
    for (float x : pos)
        if (!std::isfinite(x))
            return fail(err, "a vertex position is not a finite number");

    c->n = (uint32_t)n;
    c->pos = (float *)xmalloc(pos.size() * sizeof(float));
    c->nrm = (float *)xmalloc(nrm.size() * sizeof(float));
    c->uv = (float *)xmalloc(uv.size() * sizeof(float));
    memcpy(c->pos, pos.data(), pos.size() * sizeof(float));
    memcpy(c->nrm, nrm.data(), nrm.size() * sizeof(float));
    memcpy(c->uv, uv.data(), uv.size() * sizeof(float));
    return true;
}
