// Inlining hints: the hot per-byte path wants inlining forced, rare paths want it prevented,
// because avr-gcc -Os decides the other way round in both cases.
#ifndef ROVERLINK_CODEC_COMPILER_H
#define ROVERLINK_CODEC_COMPILER_H

#if defined(__GNUC__)
#define ROVERLINK_ALWAYS_INLINE inline __attribute__((always_inline))
#define ROVERLINK_NOINLINE __attribute__((noinline))
#else
#define ROVERLINK_ALWAYS_INLINE inline
#define ROVERLINK_NOINLINE
#endif

#endif  // ROVERLINK_CODEC_COMPILER_H
