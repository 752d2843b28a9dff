// Reference directional albedos `A(roughness, theta_o) = ∫ f (n.l) dl` of the glTF 2.0
// metallic-roughness BRDF (metallic 0, base colour 1), computed by two independent
// quadratures that agree to 1e-10, published with the conditional-sampler design.
// Included (`include!`) by the tests of `nuld_core::brdf` and of the build tool's
// albedo quadrature, so the numbers live in one place.

/// View angles (degrees) of the reference columns.
const REFERENCE_THETAS: [f64; 6] = [0.0, 30.0, 45.0, 60.0, 75.0, 85.0];
/// Roughness values of the reference rows.
const REFERENCE_ROUGHNESSES: [f64; 6] = [0.1, 0.2, 0.3, 0.5, 0.7, 1.0];
/// `A` at (`REFERENCE_ROUGHNESSES[i]`, `REFERENCE_THETAS[j]`).
const REFERENCE_ALBEDO: [[f64; 6]; 6] = [
    [0.999917, 0.999521, 1.000441, 1.025378, 1.201684, 1.572208],
    [0.999855, 0.999488, 1.000704, 1.026041, 1.188988, 1.445168],
    [0.999553, 0.999252, 1.001011, 1.025359, 1.148897, 1.294339],
    [0.996580, 0.996228, 0.997868, 1.010985, 1.056348, 1.114971],
    [0.987876, 0.987732, 0.988576, 0.993436, 1.010247, 1.037700],
    [0.972228, 0.973116, 0.974230, 0.976138, 0.981544, 0.994882],
];
/// The diffuse part `∫ (1 - F)/pi (n.l) dl` alone (any roughness) at `REFERENCE_THETAS`.
const REFERENCE_DIFFUSE: [f64; 6] = [0.959921, 0.959480, 0.958335, 0.955241, 0.947934, 0.939036];
/// The specular part `∫ F D Vis (n.l) dl` at roughness 0.1 at `REFERENCE_THETAS`.
const REFERENCE_SPECULAR_R01: [f64; 6] = [0.039996, 0.040041, 0.042106, 0.070137, 0.253750, 0.633172];
