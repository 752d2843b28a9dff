/* The C ABI's test program: tests/tests/capi.rs compiles it against the
 * freestanding libnuld_capi.a and runs each subcommand; the benchmark
 * tests/examples/capi_bench.rs runs `bench`.
 *
 *   sample FILE (--cond A,B | --normal X,Y,Z) [--instance K]
 *          [--mode table|network] [--randomize SEED] [--decoded]
 *       what `build-tool sample` prints, byte for byte (--decoded: network mode
 *       on weights decoded by nuld_decode_network, the same bits)
 *   export FILE
 *       what `build-tool export` prints for a point or direction set
 *   hostile FILE SEED COUNT
 *       COUNT corruptions of the blob (changed bytes, flipped bits, cuts,
 *       extensions, garbage after the magic) must all be refused; COUNT / 10
 *       corruptions of its header and tables with the checksum fixed may parse,
 *       and then every sample of them must be sound; every misaligned copy is
 *       refused. Prints the counts.
 *   errors FILE_2D FILE_DIRECTIONS FILE_BRDF FILE_ENVMAP
 *       every null, misaligned, unparsed and mismatched argument: one line per
 *       check, `ok` or `FAIL`, then `checks N failed F`
 *   floats SEED COUNT
 *       random f32 bit patterns as `bits,text`, text as Rust's `{}` writes it
 *   bench FILE_BRDF FILE_ENVMAP COUNT
 *       nanoseconds per call of the sampling entry points, best of 3
 */
#define _POSIX_C_SOURCE 200809L
#include "nuld.h"

#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static void die(const char *what, const char *detail) {
  fprintf(stderr, "capi_test: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
  exit(2);
}

/* --- Bytes ------------------------------------------------------------------ */

/* A file's bytes at a 16-byte aligned address, with 32 spare bytes after them. */
typedef struct {
  uint8_t *bytes;
  size_t len;
} Bytes;

static void *aligned(size_t len) {
  void *p = aligned_alloc(16, (len + 15) / 16 * 16 + 32);
  if (!p) die("out of memory", NULL);
  return p;
}

static Bytes read_file(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) die("cannot open", path);
  if (fseek(f, 0, SEEK_END) != 0) die("cannot seek", path);
  long n = ftell(f);
  if (n < 0) die("cannot tell", path);
  rewind(f);
  Bytes b = {aligned((size_t)n), (size_t)n};
  if (fread(b.bytes, 1, b.len, f) != b.len) die("cannot read", path);
  fclose(f);
  return b;
}

static NuldBlob parse_or_die(Bytes b, NuldBlobInfo *info) {
  NuldBlob blob;
  int32_t rc = nuld_blob_parse(b.bytes, b.len, &blob);
  if (rc != NULD_OK) die("nuld_blob_parse", nuld_error_message(rc));
  rc = nuld_blob_info(&blob, info);
  if (rc != NULD_OK) die("nuld_blob_info", nuld_error_message(rc));
  return blob;
}

/* --- Rust's Display of an f32 ---------------------------------------------- */

/* Whether the decimal m x 10^e reads back as x (strtof rounds ties to even,
 * which is Rust's rounding interval: closed for an even mantissa, else open). */
static int reads_back(long long m, int e, float x) {
  char text[48];
  snprintf(text, sizeof text, "%llde%d", m, e);
  return strtof(text, NULL) == x;
}

/* Writes x as Rust's `{}` writes an f32: the shortest decimal that reads back
 * as x, the closest to x if several have that length (the larger on a tie), in
 * positional notation, never with an exponent; "-" before negative numbers and
 * -0; "NaN", "inf", "-inf".
 *
 * With x's exact decimal digits D (printf's %.120e is exact, and x has at most
 * 112), for each length p = 1..9 (9 digits always read back) the two p-digit
 * decimals around x are D's first p digits and one more; every p-digit decimal
 * of the interval that reads back as x is at least as far from x as one of
 * them, so the first p at which one of the two reads back gives the digits. */
static void fmt_f32(float x, char *out) {
  if (isnan(x)) {
    strcpy(out, "NaN");
    return;
  }
  if (signbit(x)) *out++ = '-';
  x = fabsf(x);
  if (isinf(x)) {
    strcpy(out, "inf");
    return;
  }
  if (x == 0.0f) {
    strcpy(out, "0");
    return;
  }
  char exact[160], digits[160];
  snprintf(exact, sizeof exact, "%.120e", (double)x);
  size_t nd = 0;
  for (const char *c = exact; *c != 'e'; c++)
    if (*c != '.') digits[nd++] = *c;
  int e = atoi(strchr(exact, 'e') + 1); /* x = D0.D1D2... x 10^e */
  long long chosen = 0;
  int len = 0, scale = 0; /* x ~ chosen x 10^scale */
  for (int p = 1; p <= 9 && !chosen; p++) {
    long long lo = 0;
    for (int k = 0; k < p; k++) lo = lo * 10 + (digits[k] - '0');
    scale = e - (p - 1);
    /* the rest of D against one half: -1 below, 0 equal, 1 above */
    int rest = digits[p] < '5' ? -1 : digits[p] > '5' ? 1 : 0;
    for (size_t k = (size_t)p + 1; k < nd && rest == 0; k++)
      if (digits[k] != '0') rest = 1;
    int lo_ok = reads_back(lo, scale, x), hi_ok = reads_back(lo + 1, scale, x);
    if (lo_ok && (!hi_ok || rest < 0))
      chosen = lo;
    else if (hi_ok)
      chosen = lo + 1;
  }
  char text[24];
  len = snprintf(text, sizeof text, "%lld", chosen);
  int exp10 = scale + len; /* x ~ 0.TEXT x 10^exp10 */
  while (len > 1 && text[len - 1] == '0') text[--len] = '\0';
  if (exp10 <= 0) {
    out += sprintf(out, "0.");
    for (int k = 0; k < -exp10; k++) *out++ = '0';
    strcpy(out, text);
  } else if (exp10 < len) {
    memcpy(out, text, (size_t)exp10);
    out[exp10] = '.';
    strcpy(out + exp10 + 1, text + exp10);
  } else {
    strcpy(out, text);
    out += len;
    for (int k = len; k < exp10; k++) *out++ = '0';
    *out = '\0';
  }
}

/* --- sample and export ---------------------------------------------------- */

static void parse_floats(const char *text, float *out, int count, const char *flag) {
  char *end = NULL;
  for (int k = 0; k < count; k++) {
    out[k] = strtof(text, &end);
    if (end == text || (k + 1 < count ? *end != ',' : *end != '\0')) die("bad value of", flag);
    text = end + 1;
  }
}

static int cmd_sample(int argc, char **argv) {
  if (argc < 1) die("usage", "sample FILE (--cond A,B[,M] | --normal X,Y,Z) [options]");
  float at[3] = {0};
  int normal = -1, decoded = 0, randomize = 0;
  uint32_t instance = 0, mode = NULD_MODE_TABLE, seed = 0;
  for (int k = 1; k < argc; k++) {
    const char *a = argv[k], *v = k + 1 < argc ? argv[k + 1] : NULL;
    if (!strcmp(a, "--decoded")) {
      decoded = 1;
      continue;
    }
    if (!v) die("missing value of", a);
    k++;
    if (!strcmp(a, "--cond")) {
      // A,B or A,B,METALLIC (the metallic 0 unless given).
      int commas = 0;
      for (const char *q = v; *q; q++) commas += *q == ',';
      parse_floats(v, at, commas == 2 ? 3 : 2, a);
      normal = 0;
    } else if (!strcmp(a, "--normal")) {
      parse_floats(v, at, 3, a);
      normal = 1;
    } else if (!strcmp(a, "--instance")) {
      instance = (uint32_t)strtoul(v, NULL, 10);
    } else if (!strcmp(a, "--mode")) {
      mode = !strcmp(v, "network") ? NULD_MODE_NETWORK : NULD_MODE_TABLE;
    } else if (!strcmp(a, "--randomize")) {
      randomize = 1;
      seed = (uint32_t)strtoul(v, NULL, 10);
    } else {
      die("unknown option", a);
    }
  }
  if (normal < 0) die("sample needs", "--cond or --normal");
  Bytes b = read_file(argv[0]);
  NuldBlobInfo info;
  NuldBlob blob = parse_or_die(b, &info);
  float *weights = NULL;
  if (decoded) {
    weights = aligned(info.decoded_network_len * sizeof(float));
    int32_t rc = nuld_decode_network(&blob, weights, info.decoded_network_len, &blob);
    if (rc != NULD_OK) die("nuld_decode_network", nuld_error_message(rc));
  }
  printf("index,x,y,z,weight,pdf\n");
  for (uint32_t i = 0; i < info.len; i++) {
    NuldSample s;
    int32_t rc;
    const NuldVec3 n = {at[0], at[1], at[2]};
    const NuldVec2 c = {at[0], at[1]};
    if (normal && randomize)
      rc = nuld_envmap_sample_randomized(&blob, mode, n, instance, i, seed, &s);
    else if (normal)
      rc = nuld_envmap_sample(&blob, mode, n, instance, i, &s);
    else if (randomize)
      rc = nuld_conditional_sample_randomized(&blob, mode, c, at[2], instance, i, seed, &s);
    else
      rc = nuld_conditional_sample(&blob, mode, c, at[2], instance, i, &s);
    if (rc != NULD_OK) die("sampling", nuld_error_message(rc));
    char t[5][64];
    fmt_f32(s.direction[0], t[0]);
    fmt_f32(s.direction[1], t[1]);
    fmt_f32(s.direction[2], t[2]);
    fmt_f32(s.weight, t[3]);
    fmt_f32(s.pdf, t[4]);
    printf("%" PRIu32 ",%s,%s,%s,%s,%s\n", i, t[0], t[1], t[2], t[3], t[4]);
  }
  free(weights);
  free(b.bytes);
  return 0;
}

static int cmd_export(int argc, char **argv) {
  if (argc != 1) die("usage", "export FILE");
  Bytes b = read_file(argv[0]);
  NuldBlobInfo info;
  NuldBlob blob = parse_or_die(b, &info);
  int directions = info.kind == NULD_KIND_DIRECTION_SET;
  if (!directions && info.kind != NULD_KIND_POINT_SET_2D) die("export", "not a point set");
  printf(directions ? "set,index,x,y,z\n" : "set,index,x,y\n");
  for (uint32_t s = 0; s < info.sets; s++) {
    for (uint32_t i = 0; i < info.len; i++) {
      float v[3];
      int32_t rc = directions ? nuld_direction(&blob, s, i, v) : nuld_point_2d(&blob, s, i, v);
      if (rc != NULD_OK) die("reading a point", nuld_error_message(rc));
      char t[3][64];
      for (int k = 0; k < 2 + directions; k++) fmt_f32(v[k], t[k]);
      if (directions)
        printf("%" PRIu32 ",%" PRIu32 ",%s,%s,%s\n", s, i, t[0], t[1], t[2]);
      else
        printf("%" PRIu32 ",%" PRIu32 ",%s,%s\n", s, i, t[0], t[1]);
    }
  }
  free(b.bytes);
  return 0;
}

/* --- hostile -------------------------------------------------------------- */

/* splitmix64: the corruptions' random numbers. */
static uint64_t rng_state;
static uint64_t next(void) {
  uint64_t z = (rng_state += 0x9e3779b97f4a7c15u);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
  return z ^ (z >> 31);
}
static size_t below(size_t n) { return n ? (size_t)(next() % n) : 0; }

/* FNV-1a 64 of a blob, bytes 24..32 read as zero (core/FORMAT.md). */
static uint64_t checksum(const uint8_t *b, size_t len) {
  uint64_t h = 0xcbf29ce484222325u;
  for (size_t i = 0; i < len; i++) h = (h ^ (i >= 24 && i < 32 ? 0 : b[i])) * 0x100000001b3u;
  return h;
}

static long bad_outputs;

static NuldVec3 vec3(const float v[3]) {
  NuldVec3 r = {v[0], v[1], v[2]};
  return r;
}

static void expect_sample(int32_t rc, const NuldSample *s) {
  float len = sqrtf(s->direction[0] * s->direction[0] + s->direction[1] * s->direction[1] +
                    s->direction[2] * s->direction[2]);
  if (rc != NULD_OK || !(fabsf(len - 1.0f) < 1e-4f) || !isfinite(s->weight) || s->weight < 0 ||
      !isfinite(s->pdf) || s->pdf < 0)
    bad_outputs++;
}

/* Every entry point on a blob that parsed: a parsed blob must serve sound
 * samples whatever its bytes and arguments. */
static void touch_all(const NuldBlob *blob) {
  NuldBlobInfo info;
  if (nuld_blob_info(blob, &info) != NULD_OK) {
    bad_outputs++;
    return;
  }
  const uint32_t instances[3] = {0, 1, UINT32_MAX};
  if (info.kind != NULD_KIND_CONDITIONAL) {
    for (uint32_t s = 0; s < 3; s++) {
      for (uint32_t i = 0; i <= info.len + 1 && i < 300; i++) {
        float v[3] = {0, 0, 0};
        if (info.kind == NULD_KIND_POINT_SET_2D) {
          if (nuld_point_2d(blob, instances[s], i, v) != NULD_OK || !(v[0] > 0 && v[0] < 1) ||
              !(v[1] > 0 && v[1] < 1))
            bad_outputs++;
        } else {
          NuldSample d = {{0, 0, 0}, 0, 0};
          expect_sample(nuld_direction(blob, instances[s], i, d.direction), &d);
        }
      }
    }
    return;
  }
  const NuldVec2 conds[5] = {{info.cond_min[0], info.cond_min[1]},
                             {info.cond_max[0], info.cond_max[1]},
                             {0.5f * (info.cond_min[0] + info.cond_max[0]), 0.3f},
                             {NAN, INFINITY},
                             {-1e30f, 1e30f}};
  const NuldVec3 views[4] = {{0.3f, 0.4f, 0.8f}, {0, 0, 0}, {NAN, 1, INFINITY}, {1e-30f, 0, -1}};
  const float metals[5] = {0.0f, 1.0f, 0.4f, NAN, -3.0f};
  float *weights = aligned(info.decoded_network_len * sizeof(float));
  NuldBlob fast;
  int decoded = nuld_decode_network(blob, weights, info.decoded_network_len, &fast) == NULD_OK;
  if (!decoded) bad_outputs++;
  for (uint32_t i = 0; i <= info.len && i < 70; i++) {
    for (int k = 0; k < 3; k++) {
      for (uint32_t mode = 0; mode < 2; mode++) {
        const NuldBlob *b = mode && decoded ? &fast : blob;
        NuldSample s;
        for (int c = 0; c < 5; c++) {
          expect_sample(nuld_conditional_sample(b, mode, conds[c], metals[c], instances[k], i, &s), &s);
          expect_sample(
              nuld_conditional_sample_randomized(b, mode, conds[c], metals[c], instances[k], i, i * 7u, &s),
              &s);
          float pdf = -1;
          if (nuld_conditional_pdf(b, conds[c], metals[c], vec3(s.direction), &pdf) != NULD_OK ||
              !(pdf >= 0) || !isfinite(pdf))
            bad_outputs++;
        }
        for (int v = 0; v < 4; v++) {
          int32_t rc;
          if (info.target == NULD_TARGET_GLTF_BRDF) {
            rc = nuld_brdf_sample_randomized(b, mode, views[v], conds[v].x, metals[v],
                                             instances[k], i, 99, &s);
            expect_sample(rc, &s);
            float pdf = -1;
            if (nuld_brdf_pdf(b, views[v], conds[v].x, metals[v], vec3(s.direction), &pdf) !=
                    NULD_OK ||
                !(pdf >= 0) || !isfinite(pdf))
              bad_outputs++;
            rc = nuld_brdf_sample(b, mode, views[v], conds[v].x, metals[v], instances[k], i, &s);
          } else {
            rc = nuld_envmap_sample_randomized(b, mode, views[v], instances[k], i, 99, &s);
            expect_sample(rc, &s);
            rc = nuld_envmap_sample(b, mode, views[v], instances[k], i, &s);
            float pdf = -1;
            if (nuld_envmap_pdf(b, views[v], vec3(s.direction), &pdf) != NULD_OK ||
                !(pdf >= 0) || !isfinite(pdf))
              bad_outputs++;
          }
          expect_sample(rc, &s);
        }
      }
    }
  }
  free(weights);
}

static int cmd_hostile(int argc, char **argv) {
  if (argc != 3) die("usage", "hostile FILE SEED COUNT");
  Bytes b = read_file(argv[0]);
  rng_state = strtoull(argv[1], NULL, 10);
  long count = strtol(argv[2], NULL, 10);
  size_t n = b.len;
  uint8_t *m = aligned(n + 64);
  NuldBlob blob;
  if (nuld_blob_parse(b.bytes, n, &blob) != NULD_OK) die("hostile", "the blob itself is refused");
  touch_all(&blob);
  long rejected = 0, accepted_corrupt = 0, unchanged = 0, unusable_violations = 0;
  for (long t = 0; t < count; t++) {
    memcpy(m, b.bytes, n);
    size_t len = n;
    switch (t % 5) {
    case 0: /* 1 to 8 bytes changed */
      for (size_t k = 1 + below(8); k > 0; k--) m[below(n)] += (uint8_t)(1 + below(255));
      break;
    case 1: /* one bit flipped */
      m[below(n)] ^= (uint8_t)(1u << below(8));
      break;
    case 2: /* cut */
      len = below(n);
      break;
    case 3: /* extended by 1 to 64 random bytes */
      len = n + 1 + below(64);
      for (size_t k = n; k < len; k++) m[k] = (uint8_t)next();
      break;
    default: /* the magic and version kept, then garbage of any length */
      len = 16 + below(n + 48);
      for (size_t k = 16; k < len; k++) m[k] = (uint8_t)next();
      break;
    }
    int32_t rc = nuld_blob_parse(m, len, &blob);
    if (rc == NULD_OK) {
      if (len == n && !memcmp(m, b.bytes, n)) {
        unchanged++;
      } else {
        accepted_corrupt++;
      }
      touch_all(&blob);
    } else {
      rejected++;
      float v[3];
      NuldBlobInfo info;
      if (nuld_point_2d(&blob, 0, 0, v) != NULD_ERR_NOT_PARSED ||
          nuld_blob_info(&blob, &info) != NULD_ERR_NOT_PARSED)
        unusable_violations++;
    }
  }
  /* The header and the section table, with the checksum fixed: only the bounds
   * checks stand between them and the reader. */
  long rechecksummed = count / 10, re_rejected = 0, re_accepted = 0;
  size_t reach = 48 + 32 * (size_t)b.bytes[40];
  if (reach > n) reach = n;
  for (long t = 0; t < rechecksummed; t++) {
    memcpy(m, b.bytes, n);
    size_t at;
    do at = below(reach);
    while (at >= 24 && at < 32);
    m[at] = (uint8_t)next();
    uint64_t sum = checksum(m, n);
    for (int k = 0; k < 8; k++) m[24 + k] = (uint8_t)(sum >> (8 * k));
    if (nuld_blob_parse(m, n, &blob) == NULD_OK) {
      re_accepted++;
      touch_all(&blob);
    } else {
      re_rejected++;
    }
  }
  long misaligned_refused = 0;
  for (size_t off = 1; off < 16; off++) {
    memmove(m + off, b.bytes, n);
    if (nuld_blob_parse(m + off, n, &blob) == NULD_ERR_MISALIGNED) misaligned_refused++;
  }
  printf("mutations %ld rejected %ld accepted_corrupt %ld unchanged %ld unusable_violations %ld\n",
         count, rejected, accepted_corrupt, unchanged, unusable_violations);
  printf("rechecksummed %ld rejected %ld accepted %ld\n", rechecksummed, re_rejected, re_accepted);
  printf("misaligned 15 refused %ld\n", misaligned_refused);
  printf("bad_outputs %ld\n", bad_outputs);
  free(m);
  free(b.bytes);
  return 0;
}

/* --- errors --------------------------------------------------------------- */

static int checks, failed;

static void check(const char *what, int32_t got, int32_t expected) {
  checks++;
  int ok = got == expected && (got == NULD_OK || nuld_last_error() == got);
  if (!ok) failed++;
  printf("%s %s: got %d (%s), expected %d\n", ok ? "ok" : "FAIL", what, got,
         nuld_error_message(got), expected);
}

static void check_true(const char *what, int ok) {
  checks++;
  if (!ok) failed++;
  printf("%s %s\n", ok ? "ok" : "FAIL", what);
}

/* A pointer `offset` bytes past `p`: misaligned for any type with offset 1. */
static void *shifted(void *p, size_t offset) { return (void *)((uintptr_t)p + offset); }

static int cmd_errors(int argc, char **argv) {
  if (argc != 4) die("usage", "errors FILE_2D FILE_DIRECTIONS FILE_BRDF FILE_ENVMAP");
  Bytes files[4];
  NuldBlob blobs[4];
  NuldBlobInfo infos[4];
  for (int k = 0; k < 4; k++) {
    files[k] = read_file(argv[k]);
    blobs[k] = parse_or_die(files[k], &infos[k]);
  }
  const NuldBlob *pts = &blobs[0], *dirs = &blobs[1], *brdf = &blobs[2], *env = &blobs[3];
  Bytes b = files[2];
  NuldBlob out, zero;
  memset(&zero, 0, sizeof zero);
  float v[4] = {0.3f, 0.4f, 0.8f, 0};
  const NuldVec3 wo = {0.3f, 0.4f, 0.8f};
  const NuldVec2 c2 = {0.3f, 40};
  NuldSample s;
  NuldBlobInfo info;
  uint8_t *copy = aligned(b.len + 16);

  /* nuld_blob_parse */
  check("parse: null bytes", nuld_blob_parse(NULL, b.len, &out), NULD_ERR_NULL);
  check("parse: null out", nuld_blob_parse(b.bytes, b.len, NULL), NULD_ERR_NULL);
  check("parse: misaligned out", nuld_blob_parse(b.bytes, b.len, shifted(&out, 4)),
        NULD_ERR_MISALIGNED);
  memcpy(copy + 8, b.bytes, b.len);
  check("parse: bytes 8-byte aligned", nuld_blob_parse(copy + 8, b.len, &out),
        NULD_ERR_MISALIGNED);
  check("parse: an unparsed out after a failure", nuld_blob_info(&out, &info),
        NULD_ERR_NOT_PARSED);
  check("parse: len above PTRDIFF_MAX", nuld_blob_parse(b.bytes, SIZE_MAX, &out),
        NULD_ERR_TOO_LONG);
  check("parse: 0 bytes", nuld_blob_parse(b.bytes, 0, &out), NULD_ERR_TRUNCATED);
  check("parse: one byte short", nuld_blob_parse(b.bytes, b.len - 1, &out), NULD_ERR_TRUNCATED);
  memcpy(copy, b.bytes, b.len);
  memset(copy + b.len, 0, 16);
  check("parse: 16 bytes more", nuld_blob_parse(copy, b.len + 16, &out),
        NULD_ERR_TRAILING_BYTES);
  copy[0] ^= 1;
  check("parse: bad magic", nuld_blob_parse(copy, b.len, &out), NULD_ERR_BAD_MAGIC);
  copy[0] ^= 1;
  copy[b.len - 1] ^= 1;
  check("parse: a flipped bit", nuld_blob_parse(copy, b.len, &out), NULD_ERR_CHECKSUM);
  check("parse: the blob", nuld_blob_parse(b.bytes, b.len, &out), NULD_OK);

  /* the NuldBlob argument */
  const NuldBlob *bad_blobs[3] = {NULL, (const NuldBlob *)shifted(&out, 4), &zero};
  const int32_t bad_codes[3] = {NULD_ERR_NULL, NULD_ERR_MISALIGNED, NULD_ERR_NOT_PARSED};
  const char *bad_names[3] = {"null blob", "misaligned blob", "unparsed blob"};
  for (int k = 0; k < 3; k++) {
    const NuldBlob *x = bad_blobs[k];
    int32_t e = bad_codes[k];
    char what[96];
#define CHECK_BLOB(name, call)                                    \
  snprintf(what, sizeof what, "%s: %s", name, bad_names[k]); \
  check(what, call, e)
    CHECK_BLOB("info", nuld_blob_info(x, &info));
    CHECK_BLOB("decode", nuld_decode_network(x, v, 4, &out));
    CHECK_BLOB("point_2d", nuld_point_2d(x, 0, 0, v));
    CHECK_BLOB("direction", nuld_direction(x, 0, 0, v));
    CHECK_BLOB("brdf_sample", nuld_brdf_sample(x, NULD_MODE_TABLE, wo, 0.3f, 0.0f, 0, 0, &s));
    CHECK_BLOB("brdf_sample_randomized",
               nuld_brdf_sample_randomized(x, NULD_MODE_TABLE, wo, 0.3f, 0.0f, 0, 0, 1, &s));
    CHECK_BLOB("brdf_pdf", nuld_brdf_pdf(x, wo, 0.3f, 0.0f, wo, v));
    CHECK_BLOB("envmap_sample", nuld_envmap_sample(x, NULD_MODE_TABLE, wo, 0, 0, &s));
    CHECK_BLOB("envmap_sample_randomized",
               nuld_envmap_sample_randomized(x, NULD_MODE_TABLE, wo, 0, 0, 1, &s));
    CHECK_BLOB("envmap_pdf", nuld_envmap_pdf(x, wo, wo, v));
    CHECK_BLOB("conditional_sample", nuld_conditional_sample(x, NULD_MODE_TABLE, c2, 0.0f, 0, 0, &s));
    CHECK_BLOB("conditional_sample_randomized",
               nuld_conditional_sample_randomized(x, NULD_MODE_TABLE, c2, 0.0f, 0, 0, 1, &s));
    CHECK_BLOB("conditional_pdf", nuld_conditional_pdf(x, c2, 0.0f, wo, v));
#undef CHECK_BLOB
  }

  /* the other pointers */
  float *odd = shifted(copy, 1);
  check("info: null out", nuld_blob_info(brdf, NULL), NULD_ERR_NULL);
  check("info: misaligned out", nuld_blob_info(brdf, shifted(&info, 4)), NULD_ERR_MISALIGNED);
  check("point_2d: null out", nuld_point_2d(pts, 0, 0, NULL), NULD_ERR_NULL);
  check("point_2d: misaligned out", nuld_point_2d(pts, 0, 0, odd), NULD_ERR_MISALIGNED);
  check("direction: null out", nuld_direction(dirs, 0, 0, NULL), NULD_ERR_NULL);
  check("direction: misaligned out", nuld_direction(dirs, 0, 0, odd), NULD_ERR_MISALIGNED);
  check("brdf_sample: null out", nuld_brdf_sample(brdf, 0, wo, 0.3f, 0.0f, 0, 0, NULL), NULD_ERR_NULL);
  check("brdf_sample_randomized: null out",
        nuld_brdf_sample_randomized(brdf, 0, wo, 0.3f, 1.0f, 0, 0, 5, NULL), NULD_ERR_NULL);
  check("brdf_pdf: null out", nuld_brdf_pdf(brdf, wo, 0.3f, 1.0f, wo, NULL), NULD_ERR_NULL);
  check("brdf_pdf: misaligned out", nuld_brdf_pdf(brdf, wo, 0.3f, 1.0f, wo, odd),
        NULD_ERR_MISALIGNED);
  check("brdf_pdf: an environment sampler", nuld_brdf_pdf(env, wo, 0.3f, 1.0f, wo, v),
        NULD_ERR_WRONG_TARGET);
  check("brdf_sample: misaligned out",
        nuld_brdf_sample(brdf, 0, wo, 0.3f, 0.0f, 0, 0, shifted(&s, 2)), NULD_ERR_MISALIGNED);
  check("envmap_sample: null out", nuld_envmap_sample(env, 0, wo, 0, 0, NULL), NULD_ERR_NULL);
  check("envmap_sample_randomized: misaligned out",
        nuld_envmap_sample_randomized(env, 0, wo, 0, 0, 1, shifted(&s, 1)), NULD_ERR_MISALIGNED);
  check("envmap_pdf: null out", nuld_envmap_pdf(env, wo, wo, NULL), NULD_ERR_NULL);
  check("envmap_pdf: misaligned out", nuld_envmap_pdf(env, wo, wo, odd), NULD_ERR_MISALIGNED);
  check("conditional_sample: null out", nuld_conditional_sample(brdf, 0, c2, 0.0f, 0, 0, NULL),
        NULD_ERR_NULL);
  check("conditional_sample_randomized: null out",
        nuld_conditional_sample_randomized(brdf, 0, c2, 0.0f, 0, 0, 1, NULL), NULD_ERR_NULL);
  check("conditional_pdf: null out", nuld_conditional_pdf(env, c2, 0.0f, wo, NULL), NULD_ERR_NULL);
  check("decode: null buffer", nuld_decode_network(brdf, NULL, 4, &out), NULD_ERR_NULL);
  check("decode: misaligned buffer", nuld_decode_network(brdf, odd, 4, &out),
        NULD_ERR_MISALIGNED);
  check("decode: null out", nuld_decode_network(brdf, v, 4, NULL), NULD_ERR_NULL);
  check("decode: buffer above PTRDIFF_MAX", nuld_decode_network(brdf, v, SIZE_MAX / 2, &out),
        NULD_ERR_TOO_LONG);

  /* arguments the blob does not serve */
  check("brdf_sample: mode 2", nuld_brdf_sample(brdf, 2, wo, 0.3f, 0.0f, 0, 0, &s),
        NULD_ERR_UNKNOWN_MODE);
  check("envmap_sample: mode UINT32_MAX", nuld_envmap_sample(env, UINT32_MAX, wo, 0, 0, &s),
        NULD_ERR_UNKNOWN_MODE);
  check("conditional_sample: mode 7", nuld_conditional_sample(env, 7, c2, 0.0f, 0, 0, &s),
        NULD_ERR_UNKNOWN_MODE);
  check("point_2d: a direction set", nuld_point_2d(dirs, 0, 0, v), NULD_ERR_WRONG_KIND);
  check("point_2d: a sampler", nuld_point_2d(brdf, 0, 0, v), NULD_ERR_WRONG_KIND);
  check("direction: a 2D set", nuld_direction(pts, 0, 0, v), NULD_ERR_WRONG_KIND);
  check("brdf_sample: a point set", nuld_brdf_sample(pts, 0, wo, 0.3f, 0.0f, 0, 0, &s),
        NULD_ERR_WRONG_KIND);
  check("brdf_sample: an environment sampler", nuld_brdf_sample(env, 0, wo, 0.3f, 0.0f, 0, 0, &s),
        NULD_ERR_WRONG_TARGET);
  check("envmap_sample: a BRDF sampler", nuld_envmap_sample(brdf, 0, wo, 0, 0, &s),
        NULD_ERR_WRONG_TARGET);
  check("envmap_pdf: a BRDF sampler", nuld_envmap_pdf(brdf, wo, wo, v), NULD_ERR_WRONG_TARGET);
  check("conditional_sample: a direction set", nuld_conditional_sample(dirs, 0, c2, 0.0f, 0, 0, &s),
        NULD_ERR_WRONG_KIND);
  check("decode: a point set", nuld_decode_network(pts, v, 4, &out), NULD_ERR_WRONG_KIND);
  size_t need = infos[2].decoded_network_len;
  float *w = aligned(need * sizeof(float));
  check("decode: a buffer one float short", nuld_decode_network(brdf, w, need - 1, &out),
        NULD_ERR_BUFFER_TOO_SMALL);
  check("decode: out unparsed after a failure", nuld_blob_info(&out, &info), NULD_ERR_NOT_PARSED);
  NuldBlob same = *brdf;
  check("decode in place: a buffer one float short",
        nuld_decode_network(&same, w, need - 1, &same), NULD_ERR_BUFFER_TOO_SMALL);
  check("decode in place: the blob unchanged after a failure", nuld_blob_info(&same, &info),
        NULD_OK);

  /* results: written on success only; equal through copies and decoding */
  NuldSample sentinel = {{-7, -7, -7}, -7, -7}, t = sentinel;
  nuld_brdf_sample(brdf, 9, wo, 0.3f, 0.0f, 0, 0, &t);
  check_true("a failed call writes no result", !memcmp(&t, &sentinel, sizeof t));
  check("nuld_last_error after a success is the last failure",
        nuld_brdf_sample(brdf, 0, wo, 0.3f, 0.0f, 3, 1, &s), NULD_OK);
  check_true("nuld_last_error: the last failure", nuld_last_error() == NULD_ERR_UNKNOWN_MODE);
  check("decode: a long enough buffer", nuld_decode_network(brdf, w, need, &out), NULD_OK);
  NuldSample a, c;
  nuld_brdf_sample(brdf, NULD_MODE_NETWORK, wo, 0.3f, 0.0f, 3, 1, &a);
  nuld_brdf_sample(&out, NULD_MODE_NETWORK, wo, 0.3f, 0.0f, 3, 1, &c);
  check_true("decoded network mode: the same bits", !memcmp(&a, &c, sizeof a));
  NuldBlob moved;
  memcpy(&moved, env, sizeof moved);
  nuld_envmap_sample(env, NULD_MODE_TABLE, wo, 5, 2, &a);
  nuld_envmap_sample(&moved, NULD_MODE_TABLE, wo, 5, 2, &c);
  check_true("a NuldBlob copied by memcpy: the same samples", !memcmp(&a, &c, sizeof a));
  float pdf = -1;
  check("envmap_pdf: at a sample", nuld_envmap_pdf(env, wo, vec3(a.direction), &pdf), NULD_OK);
  check_true("envmap_pdf: the sample's pdf", fabsf(pdf - a.pdf) <= 1e-4f * a.pdf && pdf > 0);
  check_true("brdf sample: pdf 0 (not served yet)", s.pdf == 0);

  /* messages */
  int distinct = 1;
  for (int32_t e = 0; e >= NULD_ERR_UNKNOWN_MODE; e--)
    for (int32_t f = 0; f > e; f--)
      if (!strcmp(nuld_error_message(e), nuld_error_message(f))) distinct = 0;
  check_true("every code has a message of its own", distinct);
  check_true("an unknown code reads unknown",
             !strcmp(nuld_error_message(NULD_ERR_UNKNOWN_MODE - 1), "unknown nuld status code") &&
                 !strcmp(nuld_error_message(INT32_MIN), nuld_error_message(1)));

  printf("checks %d failed %d\n", checks, failed);
  free(w);
  free(copy);
  for (int k = 0; k < 4; k++) free(files[k].bytes);
  return 0;
}

/* --- floats --------------------------------------------------------------- */

static int cmd_floats(int argc, char **argv) {
  if (argc != 2) die("usage", "floats SEED COUNT");
  rng_state = strtoull(argv[0], NULL, 10);
  long count = strtol(argv[1], NULL, 10);
  const uint32_t special[] = {0x00000000, 0x80000000, 0x00000001, 0x007fffff, 0x00800000,
                              0x3f800000, 0x4b800000, 0x4b800001, 0x7f7fffff, 0x7f800000,
                              0xff800000, 0x7fc00000, 0x3dcccccd, 0x3e99999a, 0x5f000000,
                              0x33800000, 0x34000000, 0x4f000000, 0x3eaaaaab, 0x42c80000};
  long n_special = (long)(sizeof special / sizeof special[0]);
  for (long k = 0; k < count + n_special; k++) {
    uint32_t bits;
    if (k < n_special) {
      bits = special[k];
    } else if (k % 4 == 0) {
      /* powers of two and their neighbours, where the interval is asymmetric */
      bits = ((uint32_t)below(254) + 1) << 23 | (uint32_t)(k % 8 == 0);
    } else if (k % 4 == 1) {
      /* directions and weights: values in [-1, 1] and around them */
      bits = (uint32_t)(0x3c000000u + below(0x03800000u)) | (uint32_t)(next() & 1) << 31;
    } else {
      bits = (uint32_t)next();
    }
    float x;
    memcpy(&x, &bits, sizeof x);
    char t[64];
    fmt_f32(x, t);
    printf("%08" PRIx32 ",%s\n", bits, t);
  }
  return 0;
}

/* --- bench ---------------------------------------------------------------- */

/* The conditions every method cycles through (tests/examples/capi_bench.rs
 * makes the same ones). */
#define CONDITIONS 64
static NuldVec3 bench_views[CONDITIONS], bench_normals[CONDITIONS];
static float bench_roughness[CONDITIONS];

static void bench_conditions(void) {
  for (int c = 0; c < CONDITIONS; c++) {
    float u = ((float)((c * 37) % CONDITIONS) + 0.5f) / CONDITIONS;
    float theta = 89.0f * u * 3.14159265f / 180.0f;
    float phi = 6.28318531f * (float)fmod(c * 0.618034, 1.0);
    bench_views[c].x = sinf(theta) * cosf(phi);
    bench_views[c].y = sinf(theta) * sinf(phi);
    bench_views[c].z = cosf(theta);
    float z = 1.0f - 2.0f * ((float)c + 0.5f) / CONDITIONS;
    float r = sqrtf(1.0f - z * z);
    bench_normals[c].x = r * cosf(phi);
    bench_normals[c].y = r * sinf(phi);
    bench_normals[c].z = z;
    bench_roughness[c] = 0.1f + 0.9f * ((float)((c * 23) % CONDITIONS) + 0.5f) / CONDITIONS;
  }
}

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

typedef enum { BRDF, ENVMAP, ENVMAP_RANDOMIZED, ENVMAP_PDF } Method;

/* Best of 3 nanoseconds per call over `count` calls; sample s reads condition
 * (s / n) mod 64, instance s / n and index s mod n. */
static double time_calls(const NuldBlob *blob, Method method, uint32_t mode, uint32_t n,
                         uint32_t count, float *sink) {
  double best = INFINITY;
  for (int r = 0; r < 3; r++) {
    double t0 = now();
    for (uint32_t s = 0; s < count; s++) {
      uint32_t c = (s / n) % CONDITIONS, k = s / n, i = s % n;
      NuldSample out;
      float pdf = 0;
      switch (method) {
      case BRDF:
        nuld_brdf_sample(blob, mode, bench_views[c], bench_roughness[c], 0.0f, k, i, &out);
        break;
      case ENVMAP:
        nuld_envmap_sample(blob, mode, bench_normals[c], k, i, &out);
        break;
      case ENVMAP_RANDOMIZED:
        nuld_envmap_sample_randomized(blob, mode, bench_normals[c], k, i, k, &out);
        break;
      case ENVMAP_PDF:
        nuld_envmap_pdf(blob, bench_normals[c], bench_views[c], &pdf);
        out.direction[0] = pdf;
        break;
      }
      *sink += out.direction[0];
    }
    double ns = (now() - t0) * 1e9 / count;
    if (ns < best) best = ns;
  }
  return best;
}

static int cmd_bench(int argc, char **argv) {
  if (argc != 3) die("usage", "bench FILE_BRDF FILE_ENVMAP COUNT");
  bench_conditions();
  Bytes bb = read_file(argv[0]), be = read_file(argv[1]);
  uint32_t count = (uint32_t)strtoul(argv[2], NULL, 10);
  NuldBlobInfo ib, ie;
  NuldBlob brdf = parse_or_die(bb, &ib), env = parse_or_die(be, &ie);
  float *wb = aligned(ib.decoded_network_len * sizeof(float));
  float *we = aligned(ie.decoded_network_len * sizeof(float));
  NuldBlob brdf_fast, env_fast;
  if (nuld_decode_network(&brdf, wb, ib.decoded_network_len, &brdf_fast) != NULD_OK ||
      nuld_decode_network(&env, we, ie.decoded_network_len, &env_fast) != NULD_OK)
    die("bench", "decoding failed");
  float sink = 0;
  printf("brdf table %.2f\n", time_calls(&brdf, BRDF, NULD_MODE_TABLE, ib.len, count, &sink));
  printf("brdf network %.2f\n",
         time_calls(&brdf, BRDF, NULD_MODE_NETWORK, ib.len, count / 10, &sink));
  printf("brdf network decoded %.2f\n",
         time_calls(&brdf_fast, BRDF, NULD_MODE_NETWORK, ib.len, count / 10, &sink));
  printf("envmap table %.2f\n", time_calls(&env, ENVMAP, NULD_MODE_TABLE, ie.len, count, &sink));
  printf("envmap unbiased %.2f\n",
         time_calls(&env, ENVMAP_RANDOMIZED, NULD_MODE_TABLE, ie.len, count, &sink));
  printf("envmap network decoded %.2f\n",
         time_calls(&env_fast, ENVMAP, NULD_MODE_NETWORK, ie.len, count / 10, &sink));
  printf("envmap pdf %.2f\n", time_calls(&env, ENVMAP_PDF, 0, ie.len, count, &sink));
  fprintf(stderr, "(checksum %g)\n", (double)sink);
  free(wb);
  free(we);
  free(bb.bytes);
  free(be.bytes);
  return 0;
}

int main(int argc, char **argv) {
  if (argc < 2) die("usage", "capi_test sample|export|hostile|errors|floats|bench ...");
  const char *cmd = argv[1];
  argc -= 2;
  argv += 2;
  if (!strcmp(cmd, "sample")) return cmd_sample(argc, argv);
  if (!strcmp(cmd, "export")) return cmd_export(argc, argv);
  if (!strcmp(cmd, "hostile")) return cmd_hostile(argc, argv);
  if (!strcmp(cmd, "errors")) return cmd_errors(argc, argv);
  if (!strcmp(cmd, "floats")) return cmd_floats(argc, argv);
  if (!strcmp(cmd, "bench")) return cmd_bench(argc, argv);
  die("unknown subcommand", cmd);
  return 2;
}
