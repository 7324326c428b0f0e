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
