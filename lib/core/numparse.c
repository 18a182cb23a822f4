/* lib/core/numparse.c — exact and fast decimal to double conversion for the
 * readers of the library (core/text.h).
 *
 * Three tiers, each giving exactly strtod's correctly rounded result:
 *  1. Clinger's fast path (Clinger 1990, "How to read floating point numbers
 *     accurately"): a mantissa m <= 2^53 and |e| <= 22 are both exact
 *     doubles, so one IEEE multiply or divide rounds m * 10^e correctly.
 *     This covers the usual "%.6f" coordinates.
 *  2. Eisel-Lemire (Lemire 2021, "Number parsing at a gigabyte per second",
 *     Software: Practice and Experience 51(8); the binary64 path of the
 *     fast_float library, whose power-of-five table this reproduces for
 *     10^-100 .. 10^100): for mantissas of up to 19 digits, such as the
 *     "%.17g" this library writes. A 64x128-bit product with a truncated
 *     power of five decides the rounding; the rare ambiguous products,
 *     subnormals and overflow go on to tier 3.
 *  3. strtod on a NUL-terminated copy of the token: long mantissas, huge
 *     exponents, hex, inf/nan. strtod follows LC_NUMERIC; a program that
 *     changes it must expect '.' decimals that reach this tier to fail.
 * tests/core/test_text.c compares all of it with strtod bit for bit.
 */
#include "core/text.h"

#include <float.h>
#include <stdlib.h>

static const double pow10_exact[23] = {
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/* 128-bit truncations of 5^q, most significant bit set, for q in
 * [POW5_MIN, POW5_MAX] (generated as in fast_float's table script). */
#define POW5_MIN (-100)
#define POW5_MAX 100
static const uint64_t pow5_128[POW5_MAX - POW5_MIN + 1][2] = {
    {0xdff9772470297ebdu, 0x59787e2b93bc56f7u}, /* -100 */
    {0x8bfbea76c619ef36u, 0x57eb4edb3c55b65au}, /* -99 */
    {0xaefae51477a06b03u, 0xede622920b6b23f1u}, /* -98 */
    {0xdab99e59958885c4u, 0xe95fab368e45ecedu}, /* -97 */
    {0x88b402f7fd75539bu, 0x11dbcb0218ebb414u}, /* -96 */
    {0xaae103b5fcd2a881u, 0xd652bdc29f26a119u}, /* -95 */
    {0xd59944a37c0752a2u, 0x4be76d3346f0495fu}, /* -94 */
    {0x857fcae62d8493a5u, 0x6f70a4400c562ddbu}, /* -93 */
    {0xa6dfbd9fb8e5b88eu, 0xcb4ccd500f6bb952u}, /* -92 */
    {0xd097ad07a71f26b2u, 0x7e2000a41346a7a7u}, /* -91 */
    {0x825ecc24c873782fu, 0x8ed400668c0c28c8u}, /* -90 */
    {0xa2f67f2dfa90563bu, 0x728900802f0f32fau}, /* -89 */
    {0xcbb41ef979346bcau, 0x4f2b40a03ad2ffb9u}, /* -88 */
    {0xfea126b7d78186bcu, 0xe2f610c84987bfa8u}, /* -87 */
    {0x9f24b832e6b0f436u, 0x0dd9ca7d2df4d7c9u}, /* -86 */
    {0xc6ede63fa05d3143u, 0x91503d1c79720dbbu}, /* -85 */
    {0xf8a95fcf88747d94u, 0x75a44c6397ce912au}, /* -84 */
    {0x9b69dbe1b548ce7cu, 0xc986afbe3ee11abau}, /* -83 */
    {0xc24452da229b021bu, 0xfbe85badce996168u}, /* -82 */
    {0xf2d56790ab41c2a2u, 0xfae27299423fb9c3u}, /* -81 */
    {0x97c560ba6b0919a5u, 0xdccd879fc967d41au}, /* -80 */
    {0xbdb6b8e905cb600fu, 0x5400e987bbc1c920u}, /* -79 */
    {0xed246723473e3813u, 0x290123e9aab23b68u}, /* -78 */
    {0x9436c0760c86e30bu, 0xf9a0b6720aaf6521u}, /* -77 */
    {0xb94470938fa89bceu, 0xf808e40e8d5b3e69u}, /* -76 */
    {0xe7958cb87392c2c2u, 0xb60b1d1230b20e04u}, /* -75 */
    {0x90bd77f3483bb9b9u, 0xb1c6f22b5e6f48c2u}, /* -74 */
    {0xb4ecd5f01a4aa828u, 0x1e38aeb6360b1af3u}, /* -73 */
    {0xe2280b6c20dd5232u, 0x25c6da63c38de1b0u}, /* -72 */
    {0x8d590723948a535fu, 0x579c487e5a38ad0eu}, /* -71 */
    {0xb0af48ec79ace837u, 0x2d835a9df0c6d851u}, /* -70 */
    {0xdcdb1b2798182244u, 0xf8e431456cf88e65u}, /* -69 */
    {0x8a08f0f8bf0f156bu, 0x1b8e9ecb641b58ffu}, /* -68 */
    {0xac8b2d36eed2dac5u, 0xe272467e3d222f3fu}, /* -67 */
    {0xd7adf884aa879177u, 0x5b0ed81dcc6abb0fu}, /* -66 */
    {0x86ccbb52ea94baeau, 0x98e947129fc2b4e9u}, /* -65 */
    {0xa87fea27a539e9a5u, 0x3f2398d747b36224u}, /* -64 */
    {0xd29fe4b18e88640eu, 0x8eec7f0d19a03aadu}, /* -63 */
    {0x83a3eeeef9153e89u, 0x1953cf68300424acu}, /* -62 */
    {0xa48ceaaab75a8e2bu, 0x5fa8c3423c052dd7u}, /* -61 */
    {0xcdb02555653131b6u, 0x3792f412cb06794du}, /* -60 */
    {0x808e17555f3ebf11u, 0xe2bbd88bbee40bd0u}, /* -59 */
    {0xa0b19d2ab70e6ed6u, 0x5b6aceaeae9d0ec4u}, /* -58 */
    {0xc8de047564d20a8bu, 0xf245825a5a445275u}, /* -57 */
    {0xfb158592be068d2eu, 0xeed6e2f0f0d56712u}, /* -56 */
    {0x9ced737bb6c4183du, 0x55464dd69685606bu}, /* -55 */
    {0xc428d05aa4751e4cu, 0xaa97e14c3c26b886u}, /* -54 */
    {0xf53304714d9265dfu, 0xd53dd99f4b3066a8u}, /* -53 */
    {0x993fe2c6d07b7fabu, 0xe546a8038efe4029u}, /* -52 */
    {0xbf8fdb78849a5f96u, 0xde98520472bdd033u}, /* -51 */
    {0xef73d256a5c0f77cu, 0x963e66858f6d4440u}, /* -50 */
    {0x95a8637627989aadu, 0xdde7001379a44aa8u}, /* -49 */
    {0xbb127c53b17ec159u, 0x5560c018580d5d52u}, /* -48 */
    {0xe9d71b689dde71afu, 0xaab8f01e6e10b4a6u}, /* -47 */
    {0x9226712162ab070du, 0xcab3961304ca70e8u}, /* -46 */
    {0xb6b00d69bb55c8d1u, 0x3d607b97c5fd0d22u}, /* -45 */
    {0xe45c10c42a2b3b05u, 0x8cb89a7db77c506au}, /* -44 */
    {0x8eb98a7a9a5b04e3u, 0x77f3608e92adb242u}, /* -43 */
    {0xb267ed1940f1c61cu, 0x55f038b237591ed3u}, /* -42 */
    {0xdf01e85f912e37a3u, 0x6b6c46dec52f6688u}, /* -41 */
    {0x8b61313bbabce2c6u, 0x2323ac4b3b3da015u}, /* -40 */
    {0xae397d8aa96c1b77u, 0xabec975e0a0d081au}, /* -39 */
    {0xd9c7dced53c72255u, 0x96e7bd358c904a21u}, /* -38 */
    {0x881cea14545c7575u, 0x7e50d64177da2e54u}, /* -37 */
    {0xaa242499697392d2u, 0xdde50bd1d5d0b9e9u}, /* -36 */
    {0xd4ad2dbfc3d07787u, 0x955e4ec64b44e864u}, /* -35 */
    {0x84ec3c97da624ab4u, 0xbd5af13bef0b113eu}, /* -34 */
    {0xa6274bbdd0fadd61u, 0xecb1ad8aeacdd58eu}, /* -33 */
    {0xcfb11ead453994bau, 0x67de18eda5814af2u}, /* -32 */
    {0x81ceb32c4b43fcf4u, 0x80eacf948770ced7u}, /* -31 */
    {0xa2425ff75e14fc31u, 0xa1258379a94d028du}, /* -30 */
    {0xcad2f7f5359a3b3eu, 0x096ee45813a04330u}, /* -29 */
    {0xfd87b5f28300ca0du, 0x8bca9d6e188853fcu}, /* -28 */
    {0x9e74d1b791e07e48u, 0x775ea264cf55347eu}, /* -27 */
    {0xc612062576589ddau, 0x95364afe032a819eu}, /* -26 */
    {0xf79687aed3eec551u, 0x3a83ddbd83f52205u}, /* -25 */
    {0x9abe14cd44753b52u, 0xc4926a9672793543u}, /* -24 */
    {0xc16d9a0095928a27u, 0x75b7053c0f178294u}, /* -23 */
    {0xf1c90080baf72cb1u, 0x5324c68b12dd6339u}, /* -22 */
    {0x971da05074da7beeu, 0xd3f6fc16ebca5e04u}, /* -21 */
    {0xbce5086492111aeau, 0x88f4bb1ca6bcf585u}, /* -20 */
    {0xec1e4a7db69561a5u, 0x2b31e9e3d06c32e6u}, /* -19 */
    {0x9392ee8e921d5d07u, 0x3aff322e62439fd0u}, /* -18 */
    {0xb877aa3236a4b449u, 0x09befeb9fad487c3u}, /* -17 */
    {0xe69594bec44de15bu, 0x4c2ebe687989a9b4u}, /* -16 */
    {0x901d7cf73ab0acd9u, 0x0f9d37014bf60a11u}, /* -15 */
    {0xb424dc35095cd80fu, 0x538484c19ef38c95u}, /* -14 */
    {0xe12e13424bb40e13u, 0x2865a5f206b06fbau}, /* -13 */
    {0x8cbccc096f5088cbu, 0xf93f87b7442e45d4u}, /* -12 */
    {0xafebff0bcb24aafeu, 0xf78f69a51539d749u}, /* -11 */
    {0xdbe6fecebdedd5beu, 0xb573440e5a884d1cu}, /* -10 */
    {0x89705f4136b4a597u, 0x31680a88f8953031u}, /* -9 */
    {0xabcc77118461cefcu, 0xfdc20d2b36ba7c3eu}, /* -8 */
    {0xd6bf94d5e57a42bcu, 0x3d32907604691b4du}, /* -7 */
    {0x8637bd05af6c69b5u, 0xa63f9a49c2c1b110u}, /* -6 */
    {0xa7c5ac471b478423u, 0x0fcf80dc33721d54u}, /* -5 */
    {0xd1b71758e219652bu, 0xd3c36113404ea4a9u}, /* -4 */
    {0x83126e978d4fdf3bu, 0x645a1cac083126eau}, /* -3 */
    {0xa3d70a3d70a3d70au, 0x3d70a3d70a3d70a4u}, /* -2 */
    {0xccccccccccccccccu, 0xcccccccccccccccdu}, /* -1 */
    {0x8000000000000000u, 0x0000000000000000u}, /* 0 */
    {0xa000000000000000u, 0x0000000000000000u}, /* 1 */
    {0xc800000000000000u, 0x0000000000000000u}, /* 2 */
    {0xfa00000000000000u, 0x0000000000000000u}, /* 3 */
    {0x9c40000000000000u, 0x0000000000000000u}, /* 4 */
    {0xc350000000000000u, 0x0000000000000000u}, /* 5 */
    {0xf424000000000000u, 0x0000000000000000u}, /* 6 */
    {0x9896800000000000u, 0x0000000000000000u}, /* 7 */
    {0xbebc200000000000u, 0x0000000000000000u}, /* 8 */
    {0xee6b280000000000u, 0x0000000000000000u}, /* 9 */
    {0x9502f90000000000u, 0x0000000000000000u}, /* 10 */
    {0xba43b74000000000u, 0x0000000000000000u}, /* 11 */
    {0xe8d4a51000000000u, 0x0000000000000000u}, /* 12 */
    {0x9184e72a00000000u, 0x0000000000000000u}, /* 13 */
    {0xb5e620f480000000u, 0x0000000000000000u}, /* 14 */
    {0xe35fa931a0000000u, 0x0000000000000000u}, /* 15 */
    {0x8e1bc9bf04000000u, 0x0000000000000000u}, /* 16 */
    {0xb1a2bc2ec5000000u, 0x0000000000000000u}, /* 17 */
    {0xde0b6b3a76400000u, 0x0000000000000000u}, /* 18 */
    {0x8ac7230489e80000u, 0x0000000000000000u}, /* 19 */
    {0xad78ebc5ac620000u, 0x0000000000000000u}, /* 20 */
    {0xd8d726b7177a8000u, 0x0000000000000000u}, /* 21 */
    {0x878678326eac9000u, 0x0000000000000000u}, /* 22 */
    {0xa968163f0a57b400u, 0x0000000000000000u}, /* 23 */
    {0xd3c21bcecceda100u, 0x0000000000000000u}, /* 24 */
    {0x84595161401484a0u, 0x0000000000000000u}, /* 25 */
    {0xa56fa5b99019a5c8u, 0x0000000000000000u}, /* 26 */
    {0xcecb8f27f4200f3au, 0x0000000000000000u}, /* 27 */
    {0x813f3978f8940984u, 0x4000000000000000u}, /* 28 */
    {0xa18f07d736b90be5u, 0x5000000000000000u}, /* 29 */
    {0xc9f2c9cd04674edeu, 0xa400000000000000u}, /* 30 */
    {0xfc6f7c4045812296u, 0x4d00000000000000u}, /* 31 */
    {0x9dc5ada82b70b59du, 0xf020000000000000u}, /* 32 */
    {0xc5371912364ce305u, 0x6c28000000000000u}, /* 33 */
    {0xf684df56c3e01bc6u, 0xc732000000000000u}, /* 34 */
    {0x9a130b963a6c115cu, 0x3c7f400000000000u}, /* 35 */
    {0xc097ce7bc90715b3u, 0x4b9f100000000000u}, /* 36 */
    {0xf0bdc21abb48db20u, 0x1e86d40000000000u}, /* 37 */
    {0x96769950b50d88f4u, 0x1314448000000000u}, /* 38 */
    {0xbc143fa4e250eb31u, 0x17d955a000000000u}, /* 39 */
    {0xeb194f8e1ae525fdu, 0x5dcfab0800000000u}, /* 40 */
    {0x92efd1b8d0cf37beu, 0x5aa1cae500000000u}, /* 41 */
    {0xb7abc627050305adu, 0xf14a3d9e40000000u}, /* 42 */
    {0xe596b7b0c643c719u, 0x6d9ccd05d0000000u}, /* 43 */
    {0x8f7e32ce7bea5c6fu, 0xe4820023a2000000u}, /* 44 */
    {0xb35dbf821ae4f38bu, 0xdda2802c8a800000u}, /* 45 */
    {0xe0352f62a19e306eu, 0xd50b2037ad200000u}, /* 46 */
    {0x8c213d9da502de45u, 0x4526f422cc340000u}, /* 47 */
    {0xaf298d050e4395d6u, 0x9670b12b7f410000u}, /* 48 */
    {0xdaf3f04651d47b4cu, 0x3c0cdd765f114000u}, /* 49 */
    {0x88d8762bf324cd0fu, 0xa5880a69fb6ac800u}, /* 50 */
    {0xab0e93b6efee0053u, 0x8eea0d047a457a00u}, /* 51 */
    {0xd5d238a4abe98068u, 0x72a4904598d6d880u}, /* 52 */
    {0x85a36366eb71f041u, 0x47a6da2b7f864750u}, /* 53 */
    {0xa70c3c40a64e6c51u, 0x999090b65f67d924u}, /* 54 */
    {0xd0cf4b50cfe20765u, 0xfff4b4e3f741cf6du}, /* 55 */
    {0x82818f1281ed449fu, 0xbff8f10e7a8921a4u}, /* 56 */
    {0xa321f2d7226895c7u, 0xaff72d52192b6a0du}, /* 57 */
    {0xcbea6f8ceb02bb39u, 0x9bf4f8a69f764490u}, /* 58 */
    {0xfee50b7025c36a08u, 0x02f236d04753d5b4u}, /* 59 */
    {0x9f4f2726179a2245u, 0x01d762422c946590u}, /* 60 */
    {0xc722f0ef9d80aad6u, 0x424d3ad2b7b97ef5u}, /* 61 */
    {0xf8ebad2b84e0d58bu, 0xd2e0898765a7deb2u}, /* 62 */
    {0x9b934c3b330c8577u, 0x63cc55f49f88eb2fu}, /* 63 */
    {0xc2781f49ffcfa6d5u, 0x3cbf6b71c76b25fbu}, /* 64 */
    {0xf316271c7fc3908au, 0x8bef464e3945ef7au}, /* 65 */
    {0x97edd871cfda3a56u, 0x97758bf0e3cbb5acu}, /* 66 */
    {0xbde94e8e43d0c8ecu, 0x3d52eeed1cbea317u}, /* 67 */
    {0xed63a231d4c4fb27u, 0x4ca7aaa863ee4bddu}, /* 68 */
    {0x945e455f24fb1cf8u, 0x8fe8caa93e74ef6au}, /* 69 */
    {0xb975d6b6ee39e436u, 0xb3e2fd538e122b44u}, /* 70 */
    {0xe7d34c64a9c85d44u, 0x60dbbca87196b616u}, /* 71 */
    {0x90e40fbeea1d3a4au, 0xbc8955e946fe31cdu}, /* 72 */
    {0xb51d13aea4a488ddu, 0x6babab6398bdbe41u}, /* 73 */
    {0xe264589a4dcdab14u, 0xc696963c7eed2dd1u}, /* 74 */
    {0x8d7eb76070a08aecu, 0xfc1e1de5cf543ca2u}, /* 75 */
    {0xb0de65388cc8ada8u, 0x3b25a55f43294bcbu}, /* 76 */
    {0xdd15fe86affad912u, 0x49ef0eb713f39ebeu}, /* 77 */
    {0x8a2dbf142dfcc7abu, 0x6e3569326c784337u}, /* 78 */
    {0xacb92ed9397bf996u, 0x49c2c37f07965404u}, /* 79 */
    {0xd7e77a8f87daf7fbu, 0xdc33745ec97be906u}, /* 80 */
    {0x86f0ac99b4e8dafdu, 0x69a028bb3ded71a3u}, /* 81 */
    {0xa8acd7c0222311bcu, 0xc40832ea0d68ce0cu}, /* 82 */
    {0xd2d80db02aabd62bu, 0xf50a3fa490c30190u}, /* 83 */
    {0x83c7088e1aab65dbu, 0x792667c6da79e0fau}, /* 84 */
    {0xa4b8cab1a1563f52u, 0x577001b891185938u}, /* 85 */
    {0xcde6fd5e09abcf26u, 0xed4c0226b55e6f86u}, /* 86 */
    {0x80b05e5ac60b6178u, 0x544f8158315b05b4u}, /* 87 */
    {0xa0dc75f1778e39d6u, 0x696361ae3db1c721u}, /* 88 */
    {0xc913936dd571c84cu, 0x03bc3a19cd1e38e9u}, /* 89 */
    {0xfb5878494ace3a5fu, 0x04ab48a04065c723u}, /* 90 */
    {0x9d174b2dcec0e47bu, 0x62eb0d64283f9c76u}, /* 91 */
    {0xc45d1df942711d9au, 0x3ba5d0bd324f8394u}, /* 92 */
    {0xf5746577930d6500u, 0xca8f44ec7ee36479u}, /* 93 */
    {0x9968bf6abbe85f20u, 0x7e998b13cf4e1ecbu}, /* 94 */
    {0xbfc2ef456ae276e8u, 0x9e3fedd8c321a67eu}, /* 95 */
    {0xefb3ab16c59b14a2u, 0xc5cfe94ef3ea101eu}, /* 96 */
    {0x95d04aee3b80ece5u, 0xbba1f1d158724a12u}, /* 97 */
    {0xbb445da9ca61281fu, 0x2a8a6e45ae8edc97u}, /* 98 */
    {0xea1575143cf97226u, 0xf52d09d71a3293bdu}, /* 99 */
    {0x924d692ca61be758u, 0x593c2626705f9c56u}, /* 100 */
};

#define MAX_TOKEN 512

static const char *parse_double_slow(const char *p, const char *end, double *out)
{
    char tok[MAX_TOKEN + 1];
    size_t n = 0;
    char *stop;
    while (p + n < end && !es__is_delim(p[n])) {
        if (n == MAX_TOKEN) return NULL;
        tok[n] = p[n];
        n++;
    }
    if (n == 0) return NULL;
    tok[n] = '\0';
    /* ERANGE is not an error here: strtod's rounded result (0, a
     * subnormal or inf) is the value, and the callers reject inf. */
    *out = strtod(tok, &stop);
    if (stop != tok + n) return NULL;
    return p + n;
}

static inline void mul_64x64(uint64_t a, uint64_t b, uint64_t *hi, uint64_t *lo)
{
#ifdef __SIZEOF_INT128__
    __extension__ typedef unsigned __int128 u128;
    u128 r = (u128)a * b;
    *hi = (uint64_t)(r >> 64);
    *lo = (uint64_t)r;
#else
    uint64_t a0 = (uint32_t)a, a1 = a >> 32, b0 = (uint32_t)b, b1 = b >> 32;
    uint64_t p00 = a0 * b0, p01 = a0 * b1, p10 = a1 * b0, p11 = a1 * b1;
    uint64_t mid = (p00 >> 32) + (uint32_t)p01 + (uint32_t)p10;
    *hi = p11 + (p01 >> 32) + (p10 >> 32) + (mid >> 32);
    *lo = (mid << 32) | (uint32_t)p00;
#endif
}

/* w * 10^q for w != 0 with at most 19 digits; false when undecided (the
 * caller then asks strtod). */
static bool eisel_lemire(uint64_t w, int q, bool neg, double *out)
{
    const uint64_t *t;
    uint64_t hi, lo, hi2, lo2, mant, bits;
    int lz, upper, shift;
    int64_t power2;
    if (q < POW5_MIN || q > POW5_MAX) return false;
    t = pow5_128[q - POW5_MIN];
    lz = __builtin_clzll(w);
    w <<= lz;
    mul_64x64(w, t[0], &hi, &lo);
    if ((hi & 0x1FF) == 0x1FF) {
        /* the low bits may carry: refine with the next 64 bits of 5^q */
        mul_64x64(w, t[1], &hi2, &lo2);
        lo += hi2;
        if (hi2 > lo) hi++;
        /* still all ones: too close to a rounding boundary to decide */
        if (lo == UINT64_MAX && (hi & 0x1FF) == 0x1FF) return false;
    }
    upper = (int)(hi >> 63);
    shift = upper + 9;
    mant = hi >> shift;
    /* floor(q * log2(10)) + 63, then the exponent bias */
    power2 = ((((int64_t)152170 + 65536) * q) >> 16) + 63 + upper - lz + 1023;
    if (power2 <= 0) return false;   /* subnormal: leave it to strtod */
    /* exactly halfway between two doubles: only possible where 5^q fits
     * in 64 bits; round to even instead of up */
    if (lo <= 1 && q >= -4 && q <= 23 && (mant & 3) == 1 && (mant << shift) == hi)
        mant &= ~(uint64_t)1;
    mant += mant & 1;
    mant >>= 1;
    if (mant >= (UINT64_C(2) << 52)) {
        mant = UINT64_C(1) << 52;
        power2++;
    }
    mant &= ~(UINT64_C(1) << 52);
    if (power2 >= 0x7FF) return false;   /* overflow: strtod says inf */
    bits = mant | ((uint64_t)power2 << 52) | ((uint64_t)neg << 63);
    memcpy(out, &bits, sizeof *out);
    return true;
}

const char *es__parse_double(const char *p, const char *end, double *out)
{
    const char *s = p, *d0;
    bool neg = false, any;
    uint64_t m = 0;
    int nd = 0, e10 = 0;

    if (p < end && (*p == '-' || *p == '+')) neg = *p++ == '-';
    d0 = p;
    for (; p < end && (unsigned)(*p - '0') < 10; p++) {
        if (nd == 19) return parse_double_slow(s, end, out);
        m = m * 10 + (uint64_t)(*p - '0');
        nd += m != 0;
    }
    any = p > d0;
    if (p < end && *p == '.') {
        const char *f0 = ++p;
        for (; p < end && (unsigned)(*p - '0') < 10; p++) {
            if (nd == 19) return parse_double_slow(s, end, out);
            m = m * 10 + (uint64_t)(*p - '0');
            nd += m != 0;
            e10--;
        }
        any = any || p > f0;
    }
    if (!any) return parse_double_slow(s, end, out);
    if (p < end && (*p == 'e' || *p == 'E')) {
        bool eneg = false;
        int x = 0;
        const char *x0;
        p++;
        if (p < end && (*p == '-' || *p == '+')) eneg = *p++ == '-';
        x0 = p;
        for (; p < end && (unsigned)(*p - '0') < 10; p++)
            if (x < 100000) x = x * 10 + (*p - '0');
        if (p == x0) return parse_double_slow(s, end, out);
        e10 += eneg ? -x : x;
    }
    if (p < end && !es__is_delim(*p)) return parse_double_slow(s, end, out);
#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD == 0
    if (m == 0) {
        *out = neg ? -0.0 : 0.0;
        return p;
    }
    if (m <= (UINT64_C(1) << 53) && e10 >= -22 && e10 <= 22) {
        double v = (double)m;
        v = e10 < 0 ? v / pow10_exact[-e10] : v * pow10_exact[e10];
        *out = neg ? -v : v;
        return p;
    }
#endif
    if (m != 0 && eisel_lemire(m, e10, neg, out)) return p;
    return parse_double_slow(s, end, out);
}

const char *es__parse_int64(const char *p, const char *end, int64_t *out)
{
    bool neg = false;
    uint64_t v = 0;
    const char *d0;
    if (p < end && (*p == '-' || *p == '+')) neg = *p++ == '-';
    d0 = p;
    for (; p < end && (unsigned)(*p - '0') < 10; p++) {
        if (v > (UINT64_MAX - 9) / 10) return NULL;
        v = v * 10 + (uint64_t)(*p - '0');
    }
    if (p == d0) return NULL;
    if (neg) {
        if (v > (uint64_t)INT64_MAX + 1) return NULL;
        *out = v == (uint64_t)INT64_MAX + 1 ? INT64_MIN : -(int64_t)v;
    } else {
        if (v > (uint64_t)INT64_MAX) return NULL;
        *out = (int64_t)v;
    }
    return p;
}
