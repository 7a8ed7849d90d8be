#version 450
// Shadow views (include/shadows.glsl): meshes seen through view `shadow_view`'s
// matrix (forward Z; the graph clears the map to 1). weft-render draws the pass
// once per view into the view's atlas tile, setting `shadow_view` each time.
// Depth bias is pipeline state (the pass's `raster: (depth_bias: ...)`).
// A `ShadowCasters` pass also draws the area lights' panels, which block
// light as the path tracer's do: instances from PANEL_INSTANCES on are the
// panel mesh placed over light record gl_InstanceIndex - PANEL_INSTANCES
// (engine/render/src/recorder.rs).
#include "include/transform.glsl"
#include "include/shadows.glsl"
#include "include/area_panel.glsl"

// The first instance index that is an area light's panel (recorder.rs's
// PANEL_INSTANCES).
const uint PANEL_INSTANCES = 1u << 30;

layout(push_constant) uniform Push {
    uint shadow_view;
};

layout(location = 0) in vec3 position;

void main() {
    uint instance = uint(gl_InstanceIndex);
    vec4 world;
    if (instance >= PANEL_INSTANCES) {
        world = vec4(area_panel_point(lights[instance - PANEL_INSTANCES], position.xy), 1.0);
    } else {
        world = world_position(gl_InstanceIndex, position);
    }
    gl_Position = shadow_views[shadow_view].clip * world;
}
