// The sphere demo: its integrator table (eyelight | direct) and light rig.
#include "core/render/direct_light_integrator.h"
#include "core/render/eyelight_integrator.h"
#include "engine/renderable.h"

namespace rtfact::engine {

const std::vector<std::string>& spheresIntegrators() {
    static const std::vector<std::string> names{"eyelight", "direct"};
    return names;
}

namespace detail {

std::unique_ptr<Renderable> makeSpheresRenderable(SceneData& d, const SpheresSettings& s, Stats&) {
    requireName(spheresIntegrators(), s.integrator, "--integrator");
    std::shared_ptr<SphereScene> scene = d.spheres.scene;
    if (s.integrator == "eyelight")
        return std::make_unique<RenderableOf<SphereScene, EyeLightIntegrator>>(scene, EyeLightIntegrator{});
    // A key light above the small spheres and a dim directional fill.
    const AABB focus = d.view.focus;
    const Vec3f e = focus.extent();
    DirectLightIntegrator integ;
    integ.lights.push_back(
        PointLight{focus.center() + Vec3f(-0.6f * e.x, 2.0f * e.y + 0.5f * e.x, 0.4f * e.z), Vec3f(1.2f * dot(e, e))});
    integ.lights.push_back(DirectionalLight{{0.3f, -1.0f, -0.4f}, Vec3f(0.6f)});
    return std::make_unique<RenderableOf<SphereScene, DirectLightIntegrator>>(scene, integ);
}

}  // namespace detail
}  // namespace rtfact::engine
