// Kahan summation: after 1e5 passes a plain float sum stops absorbing increments.
#ifndef COMPENSATED_SUM_GLSL
#define COMPENSATED_SUM_GLSL

void kahan_add(inout vec4 sum, inout vec4 compensation, vec4 value) {
    precise vec4 y = value - compensation;
    precise vec4 t = sum + y;
    compensation = (t - sum) - y;
    sum = t;
}

#endif
