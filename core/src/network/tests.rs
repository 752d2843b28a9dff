extern crate std;
use super::*;
use crate::quantize::f16_decode_finite;
use std::vec::Vec;

fn shape(act: Activation) -> Shape {
    Shape::new(4, &[3, 2], act, 3).unwrap()
}

#[test]
fn param_len_counts_every_matrix_and_bias() {
    let s = shape(Activation::Relu);
    // E 4x3, W1 3x11 + 3, W2 2x3 + 2, Wo 2x2 + 2.
    assert_eq!(s.param_len(), 12 + 36 + 8 + 6);
    assert_eq!(s.multiply_adds(), 36 + 8 + 6);
    let span = |weights, fan_in, width| LayerSpan {
        weights,
        bias: weights + width * fan_in,
        fan_in,
        width,
    };
    let want = [span(12, 11, 3), span(48, 3, 2), span(56, 2, 2)];
    // E 4x3, then W1/b1 at 12/45, W2/b2 at 48/54, Wo/bo at 56/60.
    assert!(s.layers().eq(want));
    assert!(Shape::new(0, &[3], Activation::Relu, 1).is_none());
    assert!(Shape::new(4, &[], Activation::Relu, 1).is_none());
    assert!(Shape::new(4, &[129], Activation::Relu, 1).is_none());
    assert!(Shape::new(4, &[1, 1, 1, 1], Activation::Relu, 1).is_none());
}

/// The parameters of the tests' [`shape`] networks (62 of them).
fn test_params() -> [f64; 62] {
    core::array::from_fn(|j| ((j * 37 % 23) as f64 - 11.0) / 9.0)
}

/// The network of [`shape`] written out as explicit matrix products for row 2 of
/// `E`: the two hidden pre-activations and the outputs.
fn explicit_forward(
    p: &[f64; 62],
    act: Activation,
    x: &[f64; INPUTS],
) -> ([f64; 3], [f64; 2], [f64; 2]) {
    let (e, w1, b1) = (&p[6..9], &p[12..45], &p[45..48]);
    let h1: [f64; 3] = core::array::from_fn(|o| {
        b1[o] + e[o] + (0..INPUTS).map(|k| w1[o * INPUTS + k] * x[k]).sum::<f64>()
    });
    let (w2, b2) = (&p[48..54], &p[54..56]);
    let a1 = h1.map(|z| act.apply(z));
    let h2: [f64; 2] =
        core::array::from_fn(|o| b2[o] + (0..3).map(|k| w2[o * 3 + k] * a1[k]).sum::<f64>());
    let a2 = h2.map(|z| act.apply(z));
    let (wo, bo) = (&p[56..60], &p[60..62]);
    let out: [f64; 2] =
        core::array::from_fn(|o| bo[o] + (0..2).map(|k| wo[o * 2 + k] * a2[k]).sum::<f64>());
    (h1, h2, out)
}

fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() < tol)
}

/// The forward pass against the same network written out as explicit matrix
/// products.
#[test]
fn forward_equals_explicit_matrix_products() {
    for act in [Activation::Relu, Activation::Silu] {
        let s = shape(act);
        let p = test_params();
        let net = Network {
            shape: s,
            params: &p[..],
        };
        let x: [f64; INPUTS] = core::array::from_fn(|k| (k as f64 - 5.0) / 7.0);
        let i = 6; // wraps to row 2 of E
        let t = net.forward(i, x);
        assert_eq!(
            net.evaluate(i, x),
            t.output,
            "evaluate and forward agree bit for bit"
        );
        let (h1, h2, out) = explicit_forward(&p, act, &x);
        assert!(close(&t.pre[0][..3], &h1, 1e-14));
        assert!(close(&t.pre[1][..2], &h2, 1e-14));
        assert!(close(&t.output, &out, 1e-14));
        // Into a trace that holds another pass's values: every value a
        // backward pass reads is overwritten with the same bits.
        let mut into = net.forward(1, x.map(|v| 2.0 - v));
        net.forward_into(i, x, &mut into);
        assert_eq!(into.input.map(f64::to_bits), t.input.map(f64::to_bits));
        assert_eq!(into.pre[0][..3], t.pre[0][..3]);
        assert_eq!(into.pre[1][..2], t.pre[1][..2]);
        assert_eq!(into.output.map(f64::to_bits), t.output.map(f64::to_bits));
    }
}

/// With a lattice residual the outputs are the explicit matrix products plus
/// `ln(p / (1 - p))` of the shifted lattice point `p`, taken from
/// [`shifted_lattice_point`] (not read back from the features); with all-zero
/// parameters the square point is `p` itself.
#[test]
fn lattice_residual_adds_the_logit_of_the_shifted_lattice_point() {
    for act in [Activation::Relu, Activation::Silu] {
        let s = shape(act).with_lattice_residual(true);
        let (c, k, i) = ([0.3, 0.7], 5, 6); // i wraps to row 2 of E
        let x = input_features::<f64>(&s, c, 0.0, k, i);
        let z = salted_offset(k);
        let p = shifted_lattice_point(i, s.n(), s.lattice_generator(), z);
        // Away from the clamp at LATTICE_LOGIT_EPS, where the logit is exact.
        assert!(p.iter().all(|&q| (0.01..0.99).contains(&q)), "{p:?}");
        let logit = p.map(|q| Real::ln(q / (1.0 - q)));
        let params = test_params();
        let net = Network {
            shape: s,
            params: &params[..],
        };
        let (_, _, out) = explicit_forward(&params, act, &x);
        let want = [out[0] + logit[0], out[1] + logit[1]];
        let got = net.evaluate(i, x);
        assert!(close(&got, &want, 1e-12), "{got:?} vs {want:?}");
        let zero = [0.0; 62];
        let net = Network {
            shape: s,
            params: &zero[..],
        };
        assert!(close(&net.square_point(i, x), &p, 1e-12));
    }
}

/// With `M` instance slots, instance `k` reads the offset of `k mod M` and the
/// embedding row `(k mod M) n + i mod n`, placed before the first layer: the
/// outputs against explicit matrix products with that row; without slots the
/// row is `i mod n` whatever the instance.
#[test]
fn instance_slots_give_each_slot_its_own_rows_and_offset() {
    let base = Shape::new(4, &[3], Activation::Relu, 3).unwrap();
    assert_eq!(base.with_instance_slots(0), Some(base));
    assert_eq!((base.instance_key(9), base.embedding_row(9, 6)), (9, 2));
    let s = base.with_instance_slots(3).unwrap();
    assert_eq!(s.instance_slots(), 3);
    // E 12 x 3, W1 3 x 11 + 3, Wo 2 x 3 + 2.
    assert_eq!(s.param_len(), 36 + 36 + 8);
    assert_eq!(s.first_layer_offset(), 36);
    let (k, i) = (5u32, 6u32);
    assert_eq!(s.instance_key(k), 2);
    assert_eq!(s.embedding_row(k, i), 2 * 4 + 2);
    assert_eq!(s.embedding_offset(s.embedding_row(k, i)), 30);
    // Instance 5 is slot 2: the same input as instance 2, not instance 5's own.
    let c = [0.3, 0.8];
    let x = input_features::<f64>(&s, c, 0.0, k, i);
    assert_eq!(x, input_features::<f64>(&s, c, 0.0, 2, i));
    assert_ne!(x, input_features::<f64>(&base, c, 0.0, k, i));
    let p: Vec<f64> = (0..s.param_len()).map(|j| noise(j) / 2.0).collect();
    let net = Network {
        shape: s,
        params: &p[..],
    };
    let (e, w1, b1, wo, bo) = (&p[30..33], &p[36..69], &p[69..72], &p[72..78], &p[78..80]);
    let h: [f64; 3] = core::array::from_fn(|o| {
        let z = b1[o] + e[o] + (0..INPUTS).map(|j| w1[o * INPUTS + j] * x[j]).sum::<f64>();
        z.max(0.0)
    });
    let want: [f64; 2] =
        core::array::from_fn(|o| bo[o] + (0..3).map(|j| wo[o * 3 + j] * h[j]).sum::<f64>());
    let got = net.evaluate(s.embedding_row(k, i), x);
    assert!(close(&got, &want, 1e-14), "{got:?} vs {want:?}");
    // An embedding of 2^32 numbers or more is no shape.
    let wide = Shape::new(65_536, &[128], Activation::Relu, 1).unwrap();
    assert!(wide.with_instance_slots(511).is_some());
    assert!(wide.with_instance_slots(512).is_none());
}

#[test]
fn activation_derivatives_match_finite_differences() {
    for act in [Activation::Relu, Activation::Silu] {
        for x in [-3.0, -0.7, 0.4, 2.5] {
            let h = 1e-6;
            let fd = (act.apply(x + h) - act.apply(x - h)) / (2.0 * h);
            assert!((act.derivative(x) - fd).abs() < 1e-8, "{act:?} {x}");
        }
    }
}

#[test]
fn instance_offsets_are_exact_in_both_precisions_and_distinct() {
    for k in [0u32, 1, 2, 77, u32::MAX] {
        let a = instance_offset::<f32>(k);
        let b = instance_offset::<f64>(k);
        assert_eq!(a[0] as f64, b[0]);
        assert_eq!(a[1] as f64, b[1]);
        assert!(b.iter().all(|&z| (0.0..1.0).contains(&z)));
    }
    assert_ne!(instance_offset::<f64>(0), instance_offset::<f64>(1));
    // Values of an independent Python implementation of lowbias32.
    assert_eq!(hash_u32(1), 0x6889_90c0);
    assert_eq!(hash_u32(0x1234_5678), 0xf5e7_1c96);
}

/// The salted offset of instance `k` written out from its definition: the top
/// 24 bits of `hash_u32(2k ^ 0x9e3779b9)` and `hash_u32(2k ^ 0xbb67ae85)`.
fn salted_offset(k: u32) -> [f64; 2] {
    let unit = |salt: u32| (hash_u32(k.wrapping_mul(2) ^ salt) >> 8) as f64 / 16_777_216.0;
    [unit(0x9e37_79b9), unit(0xbb67_ae85)]
}

/// Under the plain hash instance 0's offset has x = 0 (its point 0 on the
/// square's edge); the salted hash feeds `hash_u32` odd numbers only, and
/// `hash_u32` maps nothing but 0 to 0 (undoing its steps on 0 gives 0), so no
/// salted offset has a zero coordinate. New shapes and blobs of code 1 use
/// it; code 0 reads as plain, other codes as nothing.
#[test]
fn salted_offsets_never_sit_on_the_edge_and_old_blobs_keep_the_plain_hash() {
    assert_eq!(instance_offset::<f64>(0)[0], 0.0);
    assert!(OFFSET_SALTS.iter().all(|s| s & 1 == 1));
    for k in (0..4096u32).chain([u32::MAX / 2, u32::MAX - 1, u32::MAX]) {
        let a = salted_instance_offset::<f32>(k);
        let b = salted_instance_offset::<f64>(k);
        assert_eq!(b, salted_offset(k));
        assert_eq!(a.map(f64::from), b);
        assert!(b.iter().all(|&z| z > 0.0 && z < 1.0), "{k}: {b:?}");
    }
    // lowbias32 undone step by step (xorshift and odd-multiplier inverses).
    let unhash = |mut x: u32| {
        let unshift = |x: u32, s: u32| (0..32 / s + 1).fold(x, |y, _| x ^ (y >> s));
        x = unshift(x, 16);
        x = x.wrapping_mul(0x43021123); // 0x846ca68b^-1 mod 2^32
        x = unshift(x, 15);
        x = x.wrapping_mul(0x1d69e2a5); // 0x7feb352d^-1 mod 2^32
        unshift(x, 16)
    };
    for x in [0u32, 1, 0x1234_5678, u32::MAX] {
        assert_eq!(unhash(hash_u32(x)), x);
    }
    assert_eq!(unhash(0), 0);
    let shape = Shape::new(8, &[4], Activation::Relu, 3).unwrap();
    assert_eq!(shape.offset_hash(), OffsetHash::Salted);
    let plain = shape.with_offset_hash(OffsetHash::Plain);
    assert_eq!(plain.instance_offset::<f64>(9), instance_offset::<f64>(9));
    let slots = shape.with_instance_slots(4).unwrap();
    assert_eq!(slots.instance_offset::<f64>(9), salted_offset(1));
    assert_eq!(OffsetHash::from_code(0), Some(OffsetHash::Plain));
    assert_eq!(OffsetHash::from_code(1), Some(OffsetHash::Salted));
    assert_eq!(OffsetHash::from_code(2), None);
}

#[test]
fn lattice_is_a_permutation_and_shift_wraps() {
    let (n, g) = (8u32, 3u32);
    let mut seen = [false; 8];
    for i in 0..n {
        let p = lattice_point::<f64>(i, n, g);
        assert_eq!(p[0], i as f64 / 8.0);
        seen[(p[1] * 8.0) as usize] = true;
    }
    assert!(seen.iter().all(|&s| s));
    let u = shifted_lattice_point::<f64>(7, n, g, [0.5, 0.9]);
    assert!((u[0] - 0.375).abs() < 1e-15 && (u[1] - (5.0 / 8.0 + 0.9 - 1.0)).abs() < 1e-15);
    assert_eq!(lattice_point::<f64>(9, n, g), lattice_point::<f64>(1, n, g));
}

#[test]
fn input_features_hold_the_shifted_and_the_plain_lattice_point() {
    let shape = Shape::new(8, &[4], Activation::Relu, 3).unwrap();
    let f = input_features::<f64>(&shape, [0.5, 0.25], 0.7, 5, 11);
    let z = salted_offset(5);
    // Index 11 wraps to 3: l = (3/8, 1/8).
    let p = [(0.375 + z[0]) % 1.0, (0.125 + z[1]) % 1.0];
    let want = [2.0 * p[0] - 1.0, 2.0 * p[1] - 1.0, -0.25, -0.75];
    assert!(f[7..].iter().zip(&want).all(|(a, b)| (a - b).abs() < 1e-15));
    assert_eq!(&f[5..7], &[2.0 * z[0] - 1.0, 2.0 * z[1] - 1.0]);
    assert_eq!(&f[..5], &condition_features([0.5, 0.25]));
}

#[test]
fn a_metallic_input_replaces_the_product_feature_and_nothing_else() {
    let plain = Shape::new(8, &[4], Activation::Relu, 3).unwrap();
    let shape = plain.with_metallic_input(true);
    assert!(shape.metallic_input() && !plain.metallic_input());
    let c = [0.5, 0.25];
    let f = |m: f64| input_features::<f64>(&shape, c, m, 5, 11);
    let base = input_features::<f64>(&plain, c, 0.3, 5, 11);
    // Without the flag the metallic is not read.
    assert_eq!(base, input_features::<f64>(&plain, c, 0.9, 5, 11));
    for (m, want) in [
        (0.0, -1.0),
        (0.25, -0.5),
        (1.0, 1.0),
        (3.0, 1.0),
        (-2.0, -1.0),
    ] {
        let x = f(m);
        assert_eq!(x[2], want, "m = {m}");
        let (mut a, mut b) = (x, base);
        a[2] = 0.0;
        b[2] = 0.0;
        assert_eq!(a, b, "only feature 2 differs (m = {m})");
    }
    assert_eq!(f(f64::NAN)[2], -1.0);
}

#[test]
fn condition_features_clamp_and_reject_nan() {
    let f = condition_features::<f64>([f64::NAN, 2.0]);
    assert_eq!(f, [-1.0, 1.0, -1.0, -1.0, 1.0]);
    let g = condition_features::<f32>([0.5, 0.25]);
    assert_eq!(g, [0.0, -0.5, -0.75, -0.5, -0.875]);
}

/// A fixed pseudo-random value in `[-1, 1)` for test data.
fn noise(j: usize) -> f64 {
    (hash_u32(j as u32) as f64 / 2f64.powi(31)) - 1.0
}

/// `dot_block` of `rows`, and `dot_block_interleaved` of the same rows
/// interleaved, against `dot` of each row, compared by `bits`.
fn assert_block_is_dot<T: Real>(rows: &[T], x: &[T], bits: impl Fn(T) -> u64, what: &str) {
    let got = dot_block(rows, x);
    let interleaved = dot_block_interleaved(&interleaved_by_hand(rows, x.len()), x);
    for (r, row) in rows.chunks_exact(x.len()).enumerate() {
        let want = bits(dot(row, x));
        let len = x.len();
        assert_eq!(bits(got[r]), want, "{what} len {len} row {r}");
        assert_eq!(
            bits(interleaved[r]),
            want,
            "{what} interleaved, len {len} row {r}"
        );
    }
}

#[test]
fn dot_blocks_give_each_row_the_bits_of_dot() {
    for len in [1, 3, 7, 8, 9, 11, 16, 31, 32, 33, 64, 128] {
        let rows: Vec<f64> = (0..UNIT_BLOCK * len)
            .map(|j| noise(j + 1000 * len))
            .collect();
        let x: Vec<f64> = (0..len).map(|j| noise(j + 7)).collect();
        assert_block_is_dot(&rows, &x, f64::to_bits, "f64");
        let rows32: Vec<f32> = rows.iter().map(|&v| v as f32).collect();
        let x32: Vec<f32> = x.iter().map(|&v| v as f32).collect();
        assert_block_is_dot(&rows32, &x32, |v| v.to_bits() as u64, "f32");
        // A block cut short dots what is there: the last rows empty (0).
        let short = dot_block(&rows[..2 * len + 1], &x);
        assert_eq!(short[1].to_bits(), dot(&rows[len..2 * len], &x).to_bits());
        assert_eq!(short[2], dot(&rows[2 * len..2 * len + 1], &x));
        assert_eq!(short[3], 0.0);
    }
    // An interleaved block cut short: no panic, whatever it sums.
    let _ = dot_block_interleaved(&[1.0f32; 5], &[1.0; 8]);
}

/// A network wide enough for blocks of units and a remainder in every layer
/// (widths 9 and 6, output 2), with an embedding: each unit equals its
/// explicit `b + (E +) dot(row, x)` bit for bit, in both precisions, and the
/// f16 storage gives the bits of the same values decoded to `f32`.
#[test]
fn blocks_of_units_give_each_unit_its_own_dot() {
    let shape = Shape::new(5, &[9, 6], Activation::Silu, 3).unwrap();
    let p: Vec<f64> = (0..shape.param_len()).map(|j| noise(j) / 2.0).collect();
    let net = Network {
        shape,
        params: &p[..],
    };
    let input: [f64; INPUTS] = core::array::from_fn(|k| noise(k + 99));
    let i = 7u32; // wraps to row 2 of E
    let t = net.forward(i, input);
    let mut x: Vec<f64> = input.to_vec();
    let mut want_out = [0.0; OUTPUTS];
    for (l, span) in shape.layers().enumerate() {
        let z: Vec<f64> = (0..span.width)
            .map(|o| {
                let mut acc = p[span.bias + o];
                if l == 0 {
                    acc += p[shape.embedding_offset(i) + o];
                }
                let row = &p[span.weights + o * span.fan_in..][..span.fan_in];
                acc + dot(row, &x)
            })
            .collect();
        if l < shape.hidden().len() {
            for (o, zo) in z.iter().enumerate() {
                assert_eq!(t.pre[l][o].to_bits(), zo.to_bits(), "layer {l} unit {o}");
            }
            x = z.iter().map(|&v| Activation::Silu.apply(v)).collect();
        } else {
            want_out.copy_from_slice(&z);
        }
    }
    assert_eq!(t.output.map(f64::to_bits), want_out.map(f64::to_bits));

    let bits: Vec<u16> = p
        .iter()
        .map(|&v| crate::quantize::f16_encode(v as f32))
        .collect();
    let decoded: Vec<f32> = bits.iter().map(|&h| f16_decode_finite(h)).collect();
    let input32 = input.map(|v| v as f32);
    let from_f16 = Network {
        shape,
        params: F16Params(&bits),
    }
    .evaluate(i, input32);
    let from_f32 = Network {
        shape,
        params: &decoded[..],
    }
    .evaluate(i, input32);
    assert_eq!(from_f16.map(f32::to_bits), from_f32.map(f32::to_bits));
}

/// Parameters cut short read as zeros in either storage: a network of three
/// hidden layers (each buffer used as input and output in turn) whose array ends
/// inside a layer evaluates, in place (`&[f32]`, a row of scratch) and decoded
/// (f16, a block of scratch), to the bits of the same array padded with zeros.
#[test]
fn parameters_cut_short_read_as_zeros_in_either_storage() {
    let shape = Shape::new(5, &[9, 6, 7], Activation::Relu, 3).unwrap();
    let bits: Vec<u16> = (0..shape.param_len())
        .map(|j| crate::quantize::f16_encode((noise(j) / 2.0) as f32))
        .collect();
    let input: [f32; INPUTS] = core::array::from_fn(|k| noise(k + 99) as f32);
    let spans: Vec<LayerSpan> = shape.layers().collect();
    // Cuts inside the first, second and last layers' weights and in the biases.
    let cuts = [
        spans[0].weights + 13,
        spans[1].weights + 20,
        spans[3].weights + 9,
        spans[3].bias + 1,
    ];
    for cut in cuts {
        let short = &bits[..cut];
        let decoded: Vec<f32> = short.iter().map(|&h| f16_decode_finite(h)).collect();
        let mut padded = decoded.clone();
        padded.resize(shape.param_len(), 0.0);
        for i in [0u32, 3] {
            let want = Network {
                shape,
                params: &padded[..],
            }
            .evaluate(i, input);
            let in_place = Network {
                shape,
                params: &decoded[..],
            }
            .evaluate(i, input);
            let from_f16 = Network {
                shape,
                params: F16Params(short),
            }
            .evaluate(i, input);
            assert_eq!(
                in_place.map(f32::to_bits),
                want.map(f32::to_bits),
                "cut {cut}"
            );
            assert_eq!(
                from_f16.map(f32::to_bits),
                want.map(f32::to_bits),
                "cut {cut}"
            );
        }
    }
}

/// `rows` (`UNIT_BLOCK` rows of `len`) interleaved by hand: weight `k` of row
/// `r` at `k UNIT_BLOCK + r`.
fn interleaved_by_hand<T: Copy>(rows: &[T], len: usize) -> Vec<T> {
    (0..UNIT_BLOCK * len)
        .map(|j| rows[(j % UNIT_BLOCK) * len + j / UNIT_BLOCK])
        .collect()
}

/// Shapes with whole blocks and remainders in every layer, one to three layers.
fn interleaving_shapes() -> [Shape; 4] {
    [
        Shape::new(5, &[9, 6], Activation::Silu, 3).unwrap(),
        Shape::new(3, &[4], Activation::Relu, 2).unwrap(),
        Shape::new(4, &[32, 32], Activation::Relu, 3).unwrap(),
        Shape::new(2, &[5, 8, 7], Activation::Silu, 1).unwrap(),
    ]
}

/// The interleaved layout moves exactly the weights of whole blocks, weight `k`
/// of a block's row `r` to `k UNIT_BLOCK + r` within the block's span, and reads
/// back in the row-major numbering.
#[test]
fn interleaving_moves_whole_blocks_only_and_reads_back_row_major() {
    for shape in interleaving_shapes() {
        let len = shape.param_len();
        let row_major: Vec<f64> = (0..len).map(|j| j as f64).collect();
        let mut p = row_major.clone();
        interleave(&shape, &mut p).unwrap();
        let mut moved = 0;
        let mut want = row_major.clone();
        for span in shape.layers() {
            for b in 0..span.width / UNIT_BLOCK {
                let start = span.weights + b * UNIT_BLOCK * span.fan_in;
                let block = &row_major[start..][..UNIT_BLOCK * span.fan_in];
                want[start..][..block.len()]
                    .copy_from_slice(&interleaved_by_hand(block, span.fan_in));
                moved += block.len();
            }
        }
        assert_eq!(p, want, "{shape:?}");
        assert!(moved > 0, "{shape:?} has a whole block");
        let mut image: Vec<usize> = (0..len).map(|j| interleaved_index(&shape, j)).collect();
        assert!((0..len).all(|j| p[image[j]] == j as f64));
        image.sort_unstable();
        assert!(image.iter().copied().eq(0..len), "a permutation");
        let view = InterleavedParams::new(shape, &p[..]);
        assert!((0..len).all(|j| Parameters::get(&view, j) == j as f64));
        assert_eq!(Parameters::get(&view, len + 3), 0.0);
        // A read across a block and its biases, and one past the end.
        let span = shape.layers().next().unwrap();
        let mut out = [0.0; 40];
        let across = &mut out[..(len - (span.bias - 20)).min(40)];
        view.read(span.bias - 20, across);
        assert!(across
            .iter()
            .enumerate()
            .all(|(k, &v)| v == (span.bias - 20 + k) as f64));
        view.read(len - 2, &mut out[..4]);
        assert_eq!(out[..4], [(len - 2) as f64, (len - 1) as f64, 0.0, 0.0]);
        assert!(interleave(&shape, &mut p[1..]).is_none());
    }
}

/// A network over the interleaved layout evaluates to the bits of the row-major
/// one, every hidden pre-activation included, in both precisions; a row or a
/// block dotted at any offset (not a block's start) reads the row-major rows.
#[test]
fn interleaved_storage_gives_the_bits_of_row_major() {
    for shape in interleaving_shapes() {
        let p: Vec<f64> = (0..shape.param_len()).map(|j| noise(j) / 2.0).collect();
        let mut q = p.clone();
        interleave(&shape, &mut q).unwrap();
        let (p32, q32): (Vec<f32>, Vec<f32>) = (
            p.iter().map(|&v| v as f32).collect(),
            q.iter().map(|&v| v as f32).collect(),
        );
        let rows = Network {
            shape,
            params: &p[..],
        };
        let inter = Network {
            shape,
            params: InterleavedParams::new(shape, &q[..]),
        };
        let rows32 = Network {
            shape,
            params: &p32[..],
        };
        let inter32 = Network {
            shape,
            params: InterleavedParams::new(shape, &q32[..]),
        };
        for i in 0..2 * shape.embedding_rows() as u32 {
            let input: [f64; INPUTS] = core::array::from_fn(|k| noise(k + 31 * i as usize));
            let (a, b) = (rows.forward(i, input), inter.forward(i, input));
            assert_eq!(a.output.map(f64::to_bits), b.output.map(f64::to_bits));
            for (l, &w) in shape.hidden().iter().enumerate() {
                let w = w as usize;
                assert!(a.pre[l][..w]
                    .iter()
                    .zip(&b.pre[l][..w])
                    .all(|(x, y)| x.to_bits() == y.to_bits()));
            }
            let input32 = input.map(|v| v as f32);
            assert_eq!(
                rows32.evaluate(i, input32).map(f32::to_bits),
                inter32.evaluate(i, input32).map(f32::to_bits),
                "{shape:?} row {i}"
            );
        }
        let span = shape.layers().next().unwrap();
        let x: Vec<f64> = (0..span.fan_in).map(|k| noise(k + 5)).collect();
        let mut scratch = [0.0; UNIT_BLOCK * MAX_WIDTH];
        for start in [
            span.weights,
            span.weights + 1,
            span.weights + span.fan_in,
            span.bias - 3,
        ] {
            let want = (&p[..]).block_dot(start, &x, &mut scratch);
            let got = inter.params.block_dot(start, &x, &mut scratch);
            assert_eq!(
                want.map(f64::to_bits),
                got.map(f64::to_bits),
                "block at {start}"
            );
            let want = (&p[..]).row_dot(start, &x, &mut scratch);
            let got = inter.params.row_dot(start, &x, &mut scratch);
            assert_eq!(want.to_bits(), got.to_bits(), "row at {start}");
        }
        // Cut short, it evaluates without a panic.
        let short = Network {
            shape,
            params: InterleavedParams::new(shape, &q32[..q32.len() / 2]),
        };
        assert!(short
            .evaluate(1, [0.5f32; INPUTS])
            .iter()
            .all(|v| v.is_finite()));
    }
}
