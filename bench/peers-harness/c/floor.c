/* The floor of the preset J^r: the two (sin, cos) pairs alone, compiled like the peers' C. */
#include <math.h>
void floor_two_sincos(const double *q, double *out) {
   out[0] = sin(q[0]);
   out[1] = cos(q[0]);
   out[2] = sin(q[1]);
   out[3] = cos(q[1]);
}
void floor_eight_sincos(const double *q, double *out) {
   for (int k = 0; k < 8; k++) {
      out[2 * k] = sin(q[k]);
      out[2 * k + 1] = cos(q[k]);
   }
}
/* The trig of the Panda (7 joints). Each angle is read once into a local and both results are
   computed before either store, so gcc merges each sin/cos pair into one sincos call, as it does in
   the SymPy C (in the loops above the store to out[2k] may alias q[k], so q[k] is read again for
   cos and no sincos is formed). */
void floor_seven_sincos(const double *q, double *out) {
   for (int k = 0; k < 7; k++) {
      const double x = q[k];
      const double s = sin(x);
      const double c = cos(x);
      out[2 * k] = s;
      out[2 * k + 1] = c;
   }
}
