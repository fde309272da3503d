// Sampling routines shared by the eye and photon stages.
#ifndef SAMPLING_GLSL
#define SAMPLING_GLSL

// An orthonormal basis around n (Duff et al. 2017, "Building an orthonormal basis, revisited").
void orthonormal_basis(vec3 n, out vec3 t, out vec3 b) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float c = n.x * n.y * a;
    t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
    b = vec3(c, s + n.y * n.y * a, -n.y);
}

// Cosine-weighted direction about n (pdf cos(theta) / pi).
vec3 sample_cosine_hemisphere(vec3 n, float u1, float u2) {
    float r = sqrt(u1);
    float phi = 2.0 * PI * u2;
    vec3 t, b;
    orthonormal_basis(n, t, b);
    return normalize(r * cos(phi) * t + r * sin(phi) * b + sqrt(max(0.0, 1.0 - u1)) * n);
}

// Uniform direction on the sphere (pdf 1 / 4 pi).
vec3 sample_sphere(float u1, float u2) {
    float z = 1.0 - 2.0 * u1;
    float r = sqrt(max(0.0, 1.0 - z * z));
    float phi = 2.0 * PI * u2;
    return vec3(r * cos(phi), r * sin(phi), z);
}

// Uniform direction in the cone about axis with cos(half angle) = cos_max (pdf 1 / solid angle).
vec3 sample_cone(vec3 axis, float cos_max, float u1, float u2) {
    float cos_t = 1.0 - u1 * (1.0 - cos_max);
    float sin_t = sqrt(max(0.0, 1.0 - cos_t * cos_t));
    float phi = 2.0 * PI * u2;
    vec3 t, b;
    orthonormal_basis(axis, t, b);
    return normalize(sin_t * cos(phi) * t + sin_t * sin(phi) * b + cos_t * axis);
}

// Uniform point on the unit disc (concentric mapping keeps strata compact).
vec2 sample_disc(float u1, float u2) {
    float a = 2.0 * u1 - 1.0, b = 2.0 * u2 - 1.0;
    if (a == 0.0 && b == 0.0) return vec2(0.0);
    float r, phi;
    if (abs(a) > abs(b)) {
        r = a;
        phi = (PI / 4.0) * (b / a);
    } else {
        r = b;
        phi = (PI / 2.0) - (PI / 4.0) * (a / b);
    }
    return r * vec2(cos(phi), sin(phi));
}

// Uniform barycentrics on a triangle.
vec2 sample_triangle(float u1, float u2) {
    float s = sqrt(u1);
    return vec2(1.0 - s, u2 * s);
}

float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

#endif
