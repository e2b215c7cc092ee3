// render/src/occlusion_oracle.cpp -- full-visibility queries for CULLIDE by occlusion queries.
// Each box is drawn as two quads facing the view: its far face, with depth writes off and
// GL_GEQUAL, inside a GL_SAMPLES_PASSED query (a sample passes where the box's far face lies at
// or behind the nearest face drawn so far, so zero samples = fully visible), then its near face
// with GL_LESS and depth writes on. Axis-aligned boxes seen along an axis have constant depth on
// those faces, and the side faces are edge-on, so two quads say everything.
#include "render/occlusion_oracle.h"

#include <GL/gl.h>
#include <GL/glext.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "osmesa_context.h"

namespace render {

namespace {

bool hasOcclusionQueries() {
    const char* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    const char* ext = reinterpret_cast<const char*>(glGetString(GL_EXTENSIONS));
    int major = 0;
    int minor = 0;
    if (version) std::sscanf(version, "%d.%d", &major, &minor);
    const bool gl15 = major > 1 || (major == 1 && minor >= 5);
    return gl15 || (ext && std::strstr(ext, "GL_ARB_occlusion_query"));
}

void quad(const collision::Aabb& b, int axis, bool far_face) {
    const int u = (axis + 1) % 3;
    const int v = (axis + 2) % 3;
    const float d = static_cast<float>(far_face ? b.max[axis] : b.min[axis]);
    const float u0 = static_cast<float>(b.min[u]);
    const float u1 = static_cast<float>(b.max[u]);
    const float v0 = static_cast<float>(b.min[v]);
    const float v1 = static_cast<float>(b.max[v]);
    glBegin(GL_QUADS);
    glVertex3f(u0, v0, d);
    glVertex3f(u1, v0, d);
    glVertex3f(u1, v1, d);
    glVertex3f(u0, v1, d);
    glEnd();
}

class OcclusionQueryOracle : public collision::VisibilityOracle {
public:
    explicit OcclusionQueryOracle(int resolution) : resolution_(resolution) {
        try {
            context_ = std::make_unique<OsMesaContext>(resolution, resolution);
        } catch (const RenderError& e) {
            throw collision::BroadPhaseUnavailable(
                std::string("broad phase 'cullide': no GL context: ") + e.what());
        }
        if (!hasOcclusionQueries()) {
            throw collision::BroadPhaseUnavailable(
                "broad phase 'cullide': this OpenGL has no occlusion queries (GL 1.5 or "
                "GL_ARB_occlusion_query)");
        }
    }
    ~OcclusionQueryOracle() override {
        if (!queries_.empty()) {
            context_->makeCurrent();
            glDeleteQueries(static_cast<GLsizei>(queries_.size()), queries_.data());
        }
    }

    int resolution() const override { return resolution_; }

    void fullyVisibleInOrder(std::span<const collision::Aabb> boxes, int axis,
                             std::span<char> visible) override {
        context_->makeCurrent();
        if (queries_.size() < boxes.size()) {
            const std::size_t old = queries_.size();
            queries_.resize(boxes.size());
            glGenQueries(static_cast<GLsizei>(boxes.size() - old), queries_.data() + old);
        }
        glViewport(0, 0, resolution_, resolution_);
        glMatrixMode(GL_PROJECTION);
        glLoadIdentity();
        glMatrixMode(GL_MODELVIEW);
        glLoadIdentity();
        glDisable(GL_CULL_FACE);
        glDisable(GL_LIGHTING);
        glDisable(GL_BLEND);
        glDisable(GL_MULTISAMPLE);
        glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        glEnable(GL_DEPTH_TEST);
        glClearDepth(1.0);
        glDepthMask(GL_TRUE);
        glClear(GL_DEPTH_BUFFER_BIT);
        for (std::size_t i = 0; i < boxes.size(); ++i) {
            glDepthMask(GL_FALSE);
            glDepthFunc(GL_GEQUAL);
            glBeginQuery(GL_SAMPLES_PASSED, queries_[i]);
            quad(boxes[i], axis, true);
            glEndQuery(GL_SAMPLES_PASSED);
            glDepthMask(GL_TRUE);
            glDepthFunc(GL_LESS);
            quad(boxes[i], axis, false);
        }
        for (std::size_t i = 0; i < boxes.size(); ++i) {
            GLuint samples = 0;
            glGetQueryObjectuiv(queries_[i], GL_QUERY_RESULT, &samples);
            visible[i] = samples == 0 ? 1 : 0;
        }
        glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        glDepthFunc(GL_LESS);
    }

private:
    int resolution_;
    std::unique_ptr<OsMesaContext> context_;
    std::vector<GLuint> queries_;
};

}  // namespace

std::unique_ptr<collision::VisibilityOracle> makeOcclusionQueryOracle(int resolution) {
    return std::make_unique<OcclusionQueryOracle>(resolution);
}

void installOcclusionQueryOracle() {
    collision::setVisibilityOracleFactory([] { return makeOcclusionQueryOracle(); });
}

}  // namespace render
