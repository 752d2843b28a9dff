// Reference directional albedos of the glTF 2.0 metal with base colour 1 (metallic 1,
// `f = D Vis`, no diffuse lobe): `A(roughness, theta_o) = ∫ D Vis (n.l) dl`, at the
// conditions of `gltf_albedo_reference.rs` (which must be included first: this file
// uses its `REFERENCE_ROUGHNESSES` and `REFERENCE_THETAS`) and at 89°. Computed by the
// build tool's half-vector Gauss–Legendre quadrature and by the adaptive Gauss–Kronrod
// quadrature over light directions of the `nuld_core::brdf` tests, which agree to
// 7e-12 at every entry; rounded to 9 decimals. The row at roughness 1 is the closed
// form `1 - mu ln(1 + 1/mu)`, `mu = cos theta_o` (GGX with alpha 1 is `D = 1/pi`).
// The albedo with metallic `m` is `(1 - m) REFERENCE_ALBEDO + m REFERENCE_METAL_ALBEDO`.
// Included (`include!`) by the tests of `nuld_core::brdf` and of the build tool's
// albedo quadrature.

/// The metal's `A` at (`REFERENCE_ROUGHNESSES[i]`, `REFERENCE_THETAS[j]`).
const REFERENCE_METAL_ALBEDO: [[f64; 6]; 6] = [
    [0.999898556, 0.999881357, 0.999846808, 0.999742123, 0.999151215, 0.992180939],
    [0.998297466, 0.997992163, 0.997372015, 0.995456550, 0.984636787, 0.918364887],
    [0.990665550, 0.988899598, 0.985364162, 0.975089471, 0.934512474, 0.885567261],
    [0.915812430, 0.904146834, 0.886243813, 0.857263436, 0.839328064, 0.900746892],
    [0.697750360, 0.692068213, 0.690493276, 0.703973487, 0.764703871, 0.873687221],
    [0.306852819, 0.335194081, 0.376774760, 0.450693856, 0.590599997, 0.780051720],
];
/// The metal's `A` at (`REFERENCE_ROUGHNESSES[i]`, 89°), the grazing end of the range.
const REFERENCE_METAL_ALBEDO_89: [f64; 6] = [0.904837840, 0.924960065, 0.958365891, 0.971168240, 0.960794957, 0.929045852];
