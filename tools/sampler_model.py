#!/usr/bin/env python3
"""The path tracer's 2D sample sets beside correlated multi-jittered ones, in NumPy (issue 34).

For each pixel count of samples N (a square: 16, 64, 256), estimates the
variance of a pixel's mean of f over N points for a few functions f on the
unit square, over `--pixels` pixels, with:

- `weft`: the first two numbers of one draw of shaders/pathtrace/random.glsl's
  SAMPLER_SOBOL (Sobol dimensions 0 and 1, the index shuffled and each
  coordinate Owen-scrambled by the Laine-Karras hash with Vegdahl's
  constants), as the shader computes them, seeded per pixel;
- `owen`: the same Sobol points under a true nested uniform scramble (a
  random flip per node, from a hash of the bits above it), to tell the hash
  from the scramble it stands for;
- `cmj`: Kensler's correlated multi-jittered sampling ("Correlated
  Multi-Jittered Sampling", Pixar 2013), which Mitsuba's `multijitter`
  sampler implements, randomly permuted per pixel; it is built for a count
  known in advance;
- `jittered` (one uniform point per cell of a sqrt(N) grid) and
  `independent`.

This is a model of the shader's numbers for analysis; the GPU test
tests/e2e/pathtrace/sampler.rs holds the shader itself to its nets.

    python3 tools/sampler_model.py
"""

import argparse

import numpy as np

MASK = 0xFFFFFFFF


def sobol_1_directions():
    """Sobol dimension 1's direction numbers (random.glsl's SOBOL_DIRECTIONS, .x):
    primitive polynomial x + 1, so each is the last xor itself shifted by one."""
    directions = [0x80000000]
    for _ in range(31):
        directions.append(directions[-1] ^ (directions[-1] >> 1))
    return directions


DIRECTIONS_1 = sobol_1_directions()

FUNCTIONS = {
    "disc": lambda x, y: (((x - 0.5) ** 2 + (y - 0.5) ** 2) < 0.09).astype(float),
    "half plane": lambda x, y: (x + 0.3 * y < 0.6).astype(float),
    "diagonal": lambda x, y: (x + y < 0.83).astype(float),
    "bands": lambda x, y: np.floor(3 * x + 2 * y * y) % 2,
    "gaussian": lambda x, y: np.exp(-((x - 0.3) ** 2 + (y - 0.6) ** 2) * 8),
    "ripple": lambda x, y: np.sin(20 * np.sqrt(x * x + y * y)),
}


def u64(x):
    return np.asarray(x, dtype=np.uint64) & MASK


def reverse_bits(x):
    x = u64(x)
    r = np.zeros_like(x)
    for i in range(32):
        r |= ((x >> i) & 1) << (31 - i)
    return r


def owen_hash(x, seed):
    x, seed = u64(x), u64(seed)
    x ^= (x * 0x3D20ADEA) & MASK
    x = (x + seed) & MASK
    x = (x * ((seed >> 16) | 1)) & MASK
    x ^= (x * 0x05526C56) & MASK
    x ^= (x * 0x53A22864) & MASK
    return x


def owen_scramble(x, seed):
    return reverse_bits(owen_hash(reverse_bits(x), seed))


def pcg4d(v):
    x, y, z, w = [(u64(a) * 1664525 + 1013904223) & MASK for a in v]
    x = (x + y * w) & MASK
    y = (y + z * x) & MASK
    z = (z + x * y) & MASK
    w = (w + y * z) & MASK
    x, y, z, w = x ^ (x >> 16), y ^ (y >> 16), z ^ (z >> 16), w ^ (w >> 16)
    x = (x + y * w) & MASK
    y = (y + z * x) & MASK
    z = (z + x * y) & MASK
    w = (w + y * z) & MASK
    return x, y, z, w


def sobol_01(index):
    """Sobol dimensions 0 and 1 of `index` as 32-bit fractions."""
    y = np.zeros_like(index)
    for bit, direction in enumerate(DIRECTIONS_1):
        y = np.where((index >> bit) & 1 == 1, y ^ direction, y)
    return reverse_bits(index), y


def unit(bits):
    return (u64(bits) >> 8).astype(np.float64) / 16777216.0


def weft_points(pixel, sample):
    """random.glsl's rng_next(...).xy for one draw of each pixel's samples."""
    seeds = pcg4d([pixel, np.zeros_like(pixel), np.full_like(pixel, 5), np.full_like(pixel, 0xA511E9B3)])
    index = owen_scramble(sample, seeds[0])
    x, y = sobol_01(index)
    return unit(owen_scramble(x, (seeds[0] * 0x9E3779B9 + seeds[1]) & MASK)), unit(owen_scramble(y, seeds[1]))


def mix(x):
    x = u64(x)
    x ^= x >> 16
    x = (x * 0x7FEB352D) & MASK
    x ^= x >> 15
    x = (x * 0x846CA68B) & MASK
    return x ^ (x >> 16)


def true_owen(v, seed):
    """A nested uniform scramble: bit b flips by a hash of the bits above it."""
    v, out = u64(v), u64(v).copy()
    for b in range(31, 7, -1):
        above = v >> (b + 1) if b < 31 else np.zeros_like(v)
        out ^= (mix(((above * 0x9E3779B1 + b * 0x85EBCA77) ^ u64(seed)) & MASK) & 1) << b
    return out


def owen_points(pixel, sample):
    seeds = pcg4d([pixel, np.zeros_like(pixel), np.full_like(pixel, 5), np.full_like(pixel, 0xA511E9B3)])
    x, y = sobol_01(u64(sample))
    return unit(true_owen(x, seeds[0])), unit(true_owen(y, seeds[1]))


def permute(i, length, p):
    """Kensler's hashed permutation of [0, length), length a power of two."""
    w = length - 1
    i, p = u64(i), u64(p)
    i ^= p
    i = (i * 0xE170893D) & MASK
    i ^= p >> 16
    i ^= (i & w) >> 4
    i ^= p >> 8
    i = (i * 0x0929EB3F) & MASK
    i ^= p >> 23
    i ^= (i & w) >> 1
    i = (i * (1 | p >> 27)) & MASK
    i = (i * 0x6935FA69) & MASK
    i ^= (i & w) >> 11
    i = (i * 0x74DCB303) & MASK
    i ^= (i & w) >> 2
    i = (i * 0x9E501CC3) & MASK
    i ^= (i & w) >> 2
    i = (i * 0xC860A3DF) & MASK
    i &= w
    i ^= i >> 5
    return (i + p) & w


def random_float(i, p):
    i, p = u64(i), u64(p)
    i ^= p
    i ^= i >> 17
    i ^= i >> 10
    i = (i * 0xB36534E5) & MASK
    i ^= i >> 12
    i ^= i >> 21
    i = (i * 0x93FC4795) & MASK
    i ^= 0xDF6E307F
    i ^= i >> 17
    i = (i * (1 | p >> 18)) & MASK
    return i.astype(np.float64) / 4294967808.0


def cmj_points(pixel, sample, n):
    m = int(round(np.sqrt(n)))
    p = u64(pcg4d([pixel, np.zeros_like(pixel), np.zeros_like(pixel), np.full_like(pixel, 0x68BC21EB)])[0])
    s = permute(sample, n, p * 0x51633E2D)
    sx = permute(s % m, m, p * 0xA511E9B3)
    sy = permute(s // m, m, p * 0x63D83595)
    jx = random_float(s, p * 0xA399D265)
    jy = random_float(s, p * 0x711AD6A5)
    return ((s % m) + (sy + jx) / m) / m, ((s // m) + (sx + jy) / m) / m


def jittered_points(rng, sample, n):
    m = int(round(np.sqrt(n)))
    return ((sample % m) + rng.random(sample.shape)) / m, ((sample // m) + rng.random(sample.shape)) / m


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pixels", type=int, default=2000)
    parser.add_argument("--counts", default="16,64,256", help="samples per pixel, squares")
    args = parser.parse_args()
    rng = np.random.default_rng(1)
    print("Variance of a pixel's mean over its N points, over "
          f"{args.pixels} pixels; the ratio is weft's over CMJ's\n")
    print("| N | f | independent | jittered | weft | true Owen | CMJ | weft / CMJ |")
    print("|---:|---|---:|---:|---:|---:|---:|---:|")
    for n in (int(c) for c in args.counts.split(",")):
        pixel = np.repeat(np.arange(args.pixels, dtype=np.uint64), n)
        sample = np.tile(np.arange(n, dtype=np.uint64), args.pixels)
        sets = {
            "independent": (rng.random(pixel.shape), rng.random(pixel.shape)),
            "jittered": jittered_points(rng, sample, n),
            "weft": weft_points(pixel, sample),
            "owen": owen_points(pixel, sample),
            "cmj": cmj_points(pixel, sample, n),
        }
        for name, f in FUNCTIONS.items():
            v = {k: f(x, y).reshape(args.pixels, n).mean(axis=1).var() for k, (x, y) in sets.items()}
            print(f"| {n} | {name} | {v['independent']:.2e} | {v['jittered']:.2e} | {v['weft']:.2e} | "
                  f"{v['owen']:.2e} | {v['cmj']:.2e} | {v['weft'] / v['cmj']:.2f} |")


if __name__ == "__main__":
    main()
