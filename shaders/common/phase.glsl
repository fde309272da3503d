// The Henyey-Greenstein phase function (Henyey and Greenstein 1941), the one Cycles' Volume
// Scatter and Principled Volume use, for the participating media of issue 31. Directions are
// the light's directions of travel: `cos_theta` is the cosine between the direction a path
// arrives along and the one it leaves along, so g > 0 scatters forward. The function is
// symmetric in the two, so eye paths and photons sample it alike.
#ifndef PHASE_GLSL
#define PHASE_GLSL

// The density over solid angle of leaving at cos_theta to the arrival direction, for an
// anisotropy g in (-1, 1): (1 - g^2) / (4 pi (1 + g^2 - 2 g cos_theta)^(3/2)).
float hg_phase(float cos_theta, float g) {
    float g2 = g * g;
    float d = 1.0 + g2 - 2.0 * g * cos_theta;
    return (1.0 - g2) / (4.0 * PI * d * sqrt(d));
}

// cos_theta drawn with the density hg_phase: u in [0, 1) through the inverse of its
// distribution, F(c) = (1 - g^2) / 2g ((1 + g^2 - 2 g c)^(-1/2) - 1 / (1 + g)); uniform in
// cos_theta for |g| below 1e-3, where the inverse loses its digits.
float hg_sample_cos(float g, float u) {
    if (abs(g) < 1e-3) return 1.0 - 2.0 * u;
    float g2 = g * g;
    float s = (1.0 - g2) / (1.0 - g + 2.0 * g * u);
    return clamp((1.0 + g2 - s * s) / (2.0 * g), -1.0, 1.0);
}

// A direction to leave along, given the unit direction `arrived` the path came along:
// cos_theta by hg_sample_cos(g, u1), the azimuth uniform by u2 (density hg_phase).
vec3 hg_sample(vec3 arrived, float g, float u1, float u2) {
    float c = hg_sample_cos(g, u1);
    float s = sqrt(max(0.0, 1.0 - c * c));
    float phi = 2.0 * PI * u2;
    vec3 t, b;
    orthonormal_basis(arrived, t, b);
    return normalize(s * cos(phi) * t + s * sin(phi) * b + c * arrived);
}

#endif
