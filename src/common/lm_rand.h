/* lm_rand.h -- the seeded random numbers the simulations share (the cornea engine's
 * simulated scans and spot noise, the dialogue's scan loop): SplitMix64 and a
 * Box-Muller Gaussian on it.  Header-only and plain C, so engines and the dialogue
 * layer use the same draws without reaching into each other; a fixed seed gives the
 * same numbers on every machine. */
#ifndef LM_RAND_H
#define LM_RAND_H
#include <math.h>
#include <stdint.h>

static inline uint64_t lm_splitmix(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* One standard normal draw (two SplitMix64 numbers; uniforms in (0, 1)). */
static inline double lm_gauss(uint64_t *s)
{
    double u1 = ((lm_splitmix(s) >> 11) + 0.5) / 9007199254740992.0;
    double u2 = ((lm_splitmix(s) >> 11) + 0.5) / 9007199254740992.0;
    return sqrt(-2 * log(u1)) * cos(2 * 3.14159265358979323846 * u2);
}

#endif
