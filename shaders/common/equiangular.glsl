// Equiangular sampling of a distance along a ray towards a point (Kulla and Fajardo 2012,
// "Importance Sampling Techniques for Path Tracing in Participating Media"), for the direct
// light of points, spots and small lights in media (issue 31): the density of t on the
// segment [t0, t1] of the ray o + t d is proportional to the inverse square distance to the
// light point c, 1 / (h^2 + (t - t_c)^2) with t_c the foot of c on the ray and h its distance
// from the ray, which cancels the light's own falloff.
#ifndef EQUIANGULAR_GLSL
#define EQUIANGULAR_GLSL

struct Equiangular {
    float t_c, h;           // the foot of the light point on the ray and its distance from it
    float theta0, theta1;   // the angles at the light of the segment's ends, seen from the foot
    float t0, t1;           // the segment
};

// The sampler for the segment [t0, t1] of the ray (o, unit d) and the light point c; h is
// kept above 1e-6 of the segment's scale, so a light on the ray line stays finite.
Equiangular equiangular_setup(vec3 o, vec3 d, vec3 c, float t0, float t1) {
    Equiangular e;
    e.t_c = dot(c - o, d);
    e.h = max(length(c - (o + e.t_c * d)), 1e-6 * max(abs(t1 - t0), 1e-6));
    e.theta0 = atan(t0 - e.t_c, e.h);
    e.theta1 = atan(t1 - e.t_c, e.h);
    e.t0 = t0;
    e.t1 = t1;
    return e;
}

// A distance drawn with equiangular_pdf from u in [0, 1), kept on the segment: near an end
// far from the foot tan is steep, and its rounding put points past it (4 of 400,000 by more
// than 1e-5 on media_probe_test's third segment), beyond a surface that ends the segment.
float equiangular_sample(Equiangular e, float u) {
    return clamp(e.t_c + e.h * tan(mix(e.theta0, e.theta1, u)), e.t0, e.t1);
}

// Its density at t (within the segment): h / ((theta1 - theta0) (h^2 + (t - t_c)^2)).
float equiangular_pdf(Equiangular e, float t) {
    float x = t - e.t_c;
    return e.h / ((e.theta1 - e.theta0) * (e.h * e.h + x * x));
}

#endif
