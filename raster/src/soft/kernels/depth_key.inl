// The depth test of softraster's fill kernels under a z-buffer format (FillTarget::depth_format):
// the value that format would store for view depth z, compared as a z-buffer of that format
// compares. Included inside each kernel unit's namespace, so no inline function is shared with
// code built for another instruction set.

// Window z of view depth z (0 at near, 1 at far), as OpenGL's projection and depth range give it.
inline double window_z(double z, double n, double f) {
  return (f * (z - n)) / (z * (f - n));
}

// What the z-buffer holds for view depth z, ordered so that smaller is nearer: a 24-bit unsigned
// normalized integer (rounded to nearest), a float, or a reversed float (1 at near, 0 at far;
// negated so that nearer is smaller, as "greater" passes on the reversed value).
inline double stored_depth(double z, const FillTarget& t) {
  const double n = t.near_plane, f = t.far_plane;
  switch (t.depth_format) {
    case kDepthD24: {
      const double w = window_z(z, n, f);
      const double clamped = w < 0.0 ? 0.0 : (w > 1.0 ? 1.0 : w);
      return __builtin_floor(clamped * 16777215.0 + 0.5);
    }
    case kDepthD32F:
      return double(float(window_z(z, n, f)));
    case kDepthD32FReversed:
      return -double(float((n * (f - z)) / (z * (f - n))));
    default:
      return z;
  }
}

// Whether a fragment at view depth z passes the depth test ("less", or "greater" reversed)
// against the view depth `stored` a pixel holds (+inf: nothing drawn yet, which any fragment
// passes). Equal stored values fail: the first drawn keeps the pixel, as in GL.
inline bool passes_depth_test(double z, double stored, const FillTarget& t) {
  if (t.depth_format == kDepthExact) return z < stored;
  if (stored == __builtin_inf()) return z == z;  // not NaN
  return stored_depth(z, t) < stored_depth(stored, t);
}
