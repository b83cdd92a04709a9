// The wide-type layer: W lanes of float or double as GCC/Clang vector extensions (one register on AVX2 / AVX-512,
// W = 1 for the scalar build), with the masks, select, min/max, sqrt and gathers the kernels
// need. Kernels are written once against these types and compiled once per instruction set (see isa_*.cpp).
//
// No include guard on purpose: each instruction-set translation unit includes this file once, inside its own
// namespace and `#pragma GCC target` region, with BATCHCOL_SIMD_BYTES set to its register width (0 = scalar).
// Intrinsics stay in kernels/simd; public headers never see them.
#if !defined(BATCHCOL_SIMD_NS) || !defined(BATCHCOL_SIMD_BYTES)
#error "include kernels/simd/wide.hpp only from an instruction-set translation unit (isa_*.cpp)"
#endif

template <class T> struct Wide {
  static constexpr int W = BATCHCOL_SIMD_BYTES == 0 ? 1 : BATCHCOL_SIMD_BYTES / int(sizeof(T));
  /// Lane integers have the width of T, so comparisons of reals are masks of this type.
  using Int = std::conditional_t<sizeof(T) == 8, std::int64_t, std::int32_t>;
  typedef T real __attribute__((vector_size(sizeof(T) * W)));
  typedef Int mask __attribute__((vector_size(sizeof(T) * W)));  // lanes are 0 (false) or -1 (true)
};

template <class T> using wreal = typename Wide<T>::real;
template <class T> using wmask = typename Wide<T>::mask;

/// Lane-wise a ? b : c (a is a mask of 0 / -1 lanes).
template <class V, class M> inline V select(M a, V b, V c) { return a ? b : c; }
template <class V> inline V wmin(V a, V b) { return a < b ? a : b; }
template <class V> inline V wmax(V a, V b) { return a < b ? b : a; }  // std::max(a, b) lane by lane

template <class T> inline wreal<T> wsqrt(wreal<T> a) {
  constexpr int bytes = int(sizeof(wreal<T>));
  if constexpr (BATCHCOL_SIMD_BYTES == 32 && bytes == 32 && sizeof(T) == 8) return _mm256_sqrt_pd(a);
  else if constexpr (BATCHCOL_SIMD_BYTES == 32 && bytes == 32 && sizeof(T) == 4) return _mm256_sqrt_ps(a);
  else if constexpr (BATCHCOL_SIMD_BYTES == 64 && bytes == 64 && sizeof(T) == 8) return _mm512_sqrt_pd(a);
  else if constexpr (BATCHCOL_SIMD_BYTES == 64 && bytes == 64 && sizeof(T) == 4) return _mm512_sqrt_ps(a);
  else {
    wreal<T> r = a;
    for (int l = 0; l < Wide<T>::W; ++l) r[l] = std::sqrt(a[l]);
    return r;
  }
}

/// Bit l set when lane l of m is true.
template <class M> inline std::uint32_t lane_bits(M m) {
  constexpr int W = int(sizeof(M) / sizeof(m[0]));
  if constexpr (BATCHCOL_SIMD_BYTES == 32 && sizeof(M) == 32 && W == 4) {
    return std::uint32_t(_mm256_movemask_pd(_mm256_castsi256_pd(__m256i(m))));
  } else if constexpr (BATCHCOL_SIMD_BYTES == 32 && sizeof(M) == 32 && W == 8) {
    return std::uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(__m256i(m))));
  } else if constexpr (BATCHCOL_SIMD_BYTES == 64 && sizeof(M) == 64 && W == 8) {
    return std::uint32_t(_mm512_cmplt_epi64_mask(__m512i(m), _mm512_setzero_si512()));
  } else if constexpr (BATCHCOL_SIMD_BYTES == 64 && sizeof(M) == 64 && W == 16) {
    return std::uint32_t(_mm512_cmplt_epi32_mask(__m512i(m), _mm512_setzero_si512()));
  } else {
    std::uint32_t bits = 0;
    for (int l = 0; l < W; ++l) bits |= (m[l] != 0 ? 1u : 0u) << l;
    return bits;
  }
}
template <class M> inline bool any(M m) { return lane_bits(m) != 0; }

/// v with the lanes set in `bits` replaced, in lane order, by src[0], src[1], ..., src[popcount(bits) - 1] (one
/// masked expand load, which reads only those values): W lanes' fields copied from consecutive slots of an array in
/// one instruction instead of one scalar store per lane. Used where has_expand_load (AVX-512): AVX2 has no expand,
/// and its emulation (a permutation table, a masked load, a blend) costs about what the ~1.5 scalar stores per field it
/// replaces there do.
constexpr bool has_expand_load = BATCHCOL_SIMD_BYTES == 64;
template <class T> __attribute__((always_inline)) inline wreal<T> expand_load(wreal<T> v, std::uint32_t bits, const T* src) {
  if constexpr (BATCHCOL_SIMD_BYTES == 64 && sizeof(T) == 4) {
    return _mm512_mask_expandloadu_ps(v, __mmask16(bits), src);
  } else if constexpr (BATCHCOL_SIMD_BYTES == 64 && sizeof(T) == 8) {
    return _mm512_mask_expandloadu_pd(v, __mmask8(bits), src);
  } else {
    for (; bits != 0; bits &= bits - 1) v[__builtin_ctz(bits)] = *src++;
    return v;
  }
}

/// Lane-wise integer -> real.
template <class T> inline wreal<T> to_real(wmask<T> i) { return __builtin_convertvector(i, wreal<T>); }

/// r[l] = *(base + byte_offset[l]) for double lanes: one hardware gather on AVX2 / AVX-512 (offsets are byte
/// distances from `base`, computed through uintptr_t, so lanes may read from different allocations).
template <class T> inline wreal<T> gather_bytes(const T* base, wmask<T> byte_offset) {
  static_assert(sizeof(T) == 8, "64-bit lanes only: the offsets are 64-bit");
  if constexpr (BATCHCOL_SIMD_BYTES == 32 && sizeof(wreal<T>) == 32) {
    return _mm256_i64gather_pd(base, __m256i(byte_offset), 1);
  } else if constexpr (BATCHCOL_SIMD_BYTES == 64 && sizeof(wreal<T>) == 64) {
    return _mm512_i64gather_pd(__m512i(byte_offset), base, 1);
  } else {
    wreal<T> r{};
    const auto start = reinterpret_cast<std::uintptr_t>(base);
    for (int l = 0; l < Wide<T>::W; ++l)
      r[l] = *reinterpret_cast<const T*>(start + static_cast<std::uintptr_t>(byte_offset[l]));
    return r;
  }
}
