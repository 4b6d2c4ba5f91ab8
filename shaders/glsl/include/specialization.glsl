// Specialisation constants: what a scene uses. The pipeline is built per scene with only
// those features compiled in ("model no more than a scene needs"). Rust sets them by name.
#ifndef DVR_SPECIALIZATION_GLSL
#define DVR_SPECIALIZATION_GLSL

#define ESTIMATOR_DELTA 0
#define ESTIMATOR_RAY_MARCH 1
#define PHASE_ISOTROPIC 0
#define PHASE_HG 1
#define PHASE_HYBRID 2

layout(constant_id = 0) const int ESTIMATOR = ESTIMATOR_DELTA;
layout(constant_id = 1) const int PHASE = PHASE_ISOTROPIC;
layout(constant_id = 2) const bool USE_EMISSION = false;
layout(constant_id = 3) const bool HAS_ENV_MAP = false;
// The volume is paged through the brick pool (include/volume.glsl). A constant, not a
// uniform: a branch on a uniform in every density lookup made the dense path's path
// tracer and temporal gradients twice as slow on lavapipe.
layout(constant_id = 4) const bool POOLED_VOLUME = false;
// Fields in the medium (1–4), packed as the volume texture's components; channel c's TF
// is the c-th segment of each LUT. One channel compiles today's single-field code.
layout(constant_id = 5) const int CHANNELS = 1;
// A label map beside the volume (include/volume.glsl, label_look): none; the medium
// tinted and masked by it; or the labels alone as solid tissue.
#define LABELS_NONE 0
#define LABELS_TINT 1
#define LABELS_SOLID 2
layout(constant_id = 6) const int LABELS = LABELS_NONE;

#endif
