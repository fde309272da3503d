// VCM's path tracing and light tracing together (vcm_techniques "pt+lt", VCM_MIS;
// docs/vcm.md): the balance heuristic over the techniques that can sample a path, with
// VCM's partial quantities (Georgiev et al. 2012; the recursion restricted to these
// techniques, written out in docs/vcm.md).
//
// Which paths are shared: light that leaves its emitter through a smooth vertex. Light tracing
// takes a caustic seen directly, L S+ D E, and the light it sends on, L S+ (D|S)* D E: its
// light subpath leaves a triangle emitter, a point or spot light (of radius 0, or a sphere),
// a sun (no eye path meets suns and lights of radius 0: their splats weigh 1) or the world,
// crosses one or more smooth vertices (every lobe of the picked leaf smooth: glass, mirrors),
// then rough and smooth ones, every rough vertex of a material of one leaf that only reflects,
// with no smooth lobe (vcm_connectable), and connects to the camera at each rough one. From
// the eye the same paths are sampled by the emission that the BSDF-sampled continuation meets
// past the smooth vertices. Every other path belongs to path tracing alone, weighted as
// before: direct light L D E too, where the light sample beats light tracing (measured: a
// point light over a plane read 17 times path tracing's pixel noise with the two weighted
// together, since light tracing's noise is in which pixel a path lands, which no density
// measures). Both sides read the same densities (bsdf_pdf of the leaf as the eye path sees it,
// the emitter's pdfs below, the camera's) and the same geometric cosines, so that the weights
// of a path add up to one whichever side computes them.
//
// n_L (photon_threads) light paths a pass against one eye path a pixel: the camera
// connection's density carries n_L, its image-plane density the pixel's film area.
#ifndef VCM_MIS_GLSL
#define VCM_MIS_GLSL
#ifdef VCM_MIS

// Whether light tracing connects a vertex of material leaf sh, of surface s, to the camera:
// one leaf (not a mix) that only reflects, without a smooth lobe (none the eye path follows),
// and no normal map.
// Objects that cast no shadow are surfaces like any other to both sides here (the eye path
// and these light paths scatter at them; only shadow rays, which carry direct light alone,
// cross them).
bool vcm_connectable(Surface s, Shading sh, vec3 wo) {
    return material_kind(s.material) != MATERIAL_MIX && light_traceable(s) &&
           bsdf_smooth_probability(sh, wo) == 0.0;
}

// The camera's density for the surface point it sees at `distance` along the unit direction
// `from_camera` from the lens point, over the surface's area (cos_surface: the geometric
// cosine there), in units of one pixel's film area: cos / (A_pixel d^2 cos^3(theta_c)) for a
// perspective camera (the film at z = -1, as light_splat_pixel_area measures it), cos /
// A_pixel for an orthographic one.
float vcm_camera_area_pdf(vec3 from_camera, float distance, float cos_surface) {
    float importance = 1.0;
    if (orthographic == 0u) {
        float cos_camera = dot(from_camera, -camera_to_world[2].xyz);
        importance = 1.0 / (distance * distance * cos_camera * cos_camera * cos_camera);
    }
    return cos_surface * importance / light_splat_pixel_area();
}

#ifdef HAS_ENVIRONMENT
// The world's light paths (emit_photon) draw the direction `from` they come from by the map's
// importance (uniformly over the sphere without a map) and their origin uniformly on the
// scene's bounding disc facing them: these are the densities, per solid angle and per unit
// area of the disc (times the world's pick probability). The disc faces the path, so the
// emitter's cosine is 1 on both sides.
float vcm_world_direction_pdf(vec3 from) {
#ifdef HAS_ENVIRONMENT_MAP
    return environment_pdf(from);
#else
    return 1.0 / (4.0 * PI);
#endif
}

float vcm_world_area_pdf(uint k) {
    return emitter_record(k, EMITTER_POWER).w / (PI * scene_radius * scene_radius);
}

// The weight of the world's radiance met by the eye path along `from` (lt its quantity
// before leaving the scene): 1 / (1 + p_A p_dir lt).
float vcm_world_emission_weight(vec3 from, float lt) {
    uint k = emitter_count - 1u;  // the world is the last emitter
    if (!(lt > 0.0) || emitter_count == 0u || emitter_kind(k) != EMITTER_ENVIRONMENT)
        return 1.0;
    return 1.0 / (1.0 + vcm_world_area_pdf(k) * vcm_world_direction_pdf(from) * lt);
}
#endif

// The density per solid angle with which emitter k's light paths leave along `travel` (unit,
// from the emitter's point `from`), for the emitters whose paths light tracing takes: a
// triangle's cosine about its emitting face (either face, picked evenly, for a two-sided
// one), a point light's uniform sphere, a sphere light's cosine about its normal at `from`,
// a spot's uniform cone, the world's vcm_world_direction_pdf. 0 for every other emitter (suns
// and spots of radius 0: vcm_unmet_emitter).
float vcm_emission_direction_pdf(uint k, vec3 from, vec3 travel) {
    vec4 a = emitter_record(k, EMITTER_A), b = emitter_record(k, EMITTER_B);
    int kind = floatBitsToInt(a.w) & EMITTER_KIND_MASK;
#ifdef HAS_TRIANGLE_EMITTERS
    if (kind == EMITTER_TRIANGLE) {
        vec4 c = emitter_record(k, EMITTER_C);
        float cos_l = dot(triangle_normal(a.xyz, b.xyz, c.xyz), travel);
        if (triangle_emitter_two_sided(b.w)) return abs(cos_l) / (2.0 * PI);
        return max(cos_l, 0.0) / PI;
    }
#endif
#ifdef HAS_POINT_LIGHTS
    if (kind == EMITTER_POINT) {
        if (b.w <= 0.0) return 1.0 / (4.0 * PI);
        return max(dot(normalize(from - a.xyz), travel), 0.0) / PI;
    }
#endif
#ifdef HAS_SPOT_LIGHTS
    // A spot of a radius: uniform in its cone (the smooth edge weighs the flux, not the
    // density), from the sphere the eye paths meet (vcm_spot_sphere_origin).
    if (kind == EMITTER_SPOT) {
        vec4 c = emitter_record(k, EMITTER_C);
        if (!(c.y > 0.0) || dot(b.xyz, travel) < b.w) return 0.0;
        return 1.0 / (2.0 * PI * (1.0 - b.w));
    }
#endif
#ifdef HAS_ENVIRONMENT
    if (kind == EMITTER_ENVIRONMENT) return vcm_world_direction_pdf(-travel);
#endif
    return 0.0;
}

// Whether no eye path can meet emitter k: a sun (the eye's rays escape to the world alone)
// or a spot of radius 0. Path tracing cannot sample their caustics (its light sample does not
// cross glass or mirrors), so light tracing takes them whole: dVC = 0, the splat's weight 1.
bool vcm_unmet_emitter(uint k) {
    int kind = emitter_kind(k);
#ifdef HAS_SUN_LIGHTS
    if (kind == EMITTER_SUN) return true;
#endif
#ifdef HAS_SPOT_LIGHTS
    if (kind == EMITTER_SPOT) return !(emitter_record(k, EMITTER_C).y > 0.0);
#endif
    return false;
}

#ifdef HAS_SPOT_LIGHTS
// A spot of radius r is a sphere to the eye paths (common/sphere_lights.glsl: radiance I(w) /
// pi r^2 towards w, whatever point of it is seen), while emit_photon sends the photons from a
// disc facing the spot's axis. So that both sides of VCM sample the same light, its light
// paths here leave the sphere: `origin` (emit_photon's point of the axis' disc) is moved to
// the same place on the disc facing `travel`, then out to the sphere's surface, uniform over
// the sphere's outline as seen along travel.
vec3 vcm_spot_sphere_origin(uint k, vec3 origin, vec3 travel) {
    vec3 centre = emitter_record(k, EMITTER_A).xyz, axis = emitter_record(k, EMITTER_B).xyz;
    float r = emitter_record(k, EMITTER_C).y;
    vec3 t, bt, t2, bt2;
    orthonormal_basis(axis, t, bt);
    orthonormal_basis(travel, t2, bt2);
    vec2 q = vec2(dot(origin - centre, t), dot(origin - centre, bt));
    return centre + q.x * t2 + q.y * bt2 + travel * sqrt(max(0.0, r * r - dot(q, q)));
}

// dVC at the start of such a path: the cosine at the sphere over its emission density, per
// unit area of the sphere and solid angle, p_pick (cos / pi r^2) p_dir: pi r^2 / (p_pick p_dir).
float vcm_spot_start(uint k, float p_direction) {
    float r = emitter_record(k, EMITTER_C).y;
    return PI * r * r / (emitter_record(k, EMITTER_POWER).w * p_direction);
}
#endif

#ifdef HAS_POINT_LIGHTS
// A sphere light's density of its light paths' origins per unit area, p_pick / (4 pi r^2).
float vcm_sphere_area_pdf(uint k) {
    float r = emitter_record(k, EMITTER_B).w;
    return emitter_record(k, EMITTER_POWER).w / (4.0 * PI * r * r);
}
#endif

// A triangle emitter's density of its light paths' origins per unit area, p_pick / A (light
// samples draw its points with the same density, so p_e / p_light = 1 for the light sample).
float vcm_triangle_area_pdf(uint k) {
    vec3 a = emitter_record(k, EMITTER_A).xyz;
    float area = 0.5 * length(cross(emitter_record(k, EMITTER_B).xyz - a,
                                    emitter_record(k, EMITTER_C).xyz - a));
    return area > 0.0 ? emitter_record(k, EMITTER_POWER).w / area : 0.0;
}

// The weight of emission met by the eye path at an emissive triangle (packed triangle t),
// travelling along `travel` from it: lt_here is the eye path's light tracing quantity at
// that surface (0 where light tracing cannot sample the path), p_e its emission density
// (area and direction). Path tracing's emission hit against light tracing: 1 / (1 + p_e lt).
float vcm_emission_weight(int t, vec3 travel, float lt_here) {
#ifdef HAS_EMITTER_MIS
    if (!(lt_here > 0.0)) return 1.0;
    int k = triangle_emitter(t);
    if (k < 0) return 1.0;
    float p_e = vcm_triangle_area_pdf(uint(k)) *
                vcm_emission_direction_pdf(uint(k), vec3(0.0), travel);
    return 1.0 / (1.0 + p_e * lt_here);
#else
    return 1.0;
#endif
}

#ifdef SPHERE_LIGHT_RECORDS
// The emitter record of the sphere light hit_sphere_light (common/sphere_lights.glsl) found
// last.
uint sphere_light_record = 0u;

// The same for the sphere light the eye path met last (hit_sphere_light): with lt the eye
// path's quantity before the hit, p_A p_dir lt / cos_l = p_pick lt / (4 pi^2 r^2) (the
// cosine at the sphere cancels); a spot's p_pick lt / (pi r^2 Omega) (vcm_spot_start).
float vcm_sphere_emission_weight(float lt) {
    uint k = sphere_light_record;
    if (!(lt > 0.0)) return 1.0;
#ifdef HAS_SPOT_LIGHTS
    if (emitter_kind(k) == EMITTER_SPOT) {
        float cos_half = emitter_record(k, EMITTER_B).w;
        return 1.0 / (1.0 + lt / vcm_spot_start(k, 1.0 / (2.0 * PI * (1.0 - cos_half))));
    }
#endif
#ifdef HAS_POINT_LIGHTS
    if (emitter_kind(k) == EMITTER_POINT) return 1.0 / (1.0 + vcm_sphere_area_pdf(k) * lt / PI);
#endif
    return 1.0;
}
#endif

#endif
#endif
