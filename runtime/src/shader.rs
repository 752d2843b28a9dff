//! Shader-side sampling: the runtime's sampling functions in WGSL, over the blob's
//! bytes uploaded unchanged as one GPU storage buffer (core/FORMAT.md, "std430 view
//! for shaders").
//!
//! [`WGSL`] is a library of functions, one per runtime function, each named
//! `nuld_` + the Rust name (`nuld_sample` is [`ConditionalSampler::sample`],
//! `nuld_sample_metallic` is [`ConditionalSampler::sample_metallic`],
//! `nuld_sample_brdf(wo, roughness, metallic, instance, i)` is
//! [`BrdfSampler::sample`], `nuld_pdf_brdf` is [`BrdfSampler::pdf`],
//! `nuld_direction` is [`DirectionSet::direction`], ...), with a comment naming its
//! Rust twin. Every point warp is there: the equal-area maps, the BRDF mixture,
//! the environment tree and the tabulated BRDF prior with its metallic (warp 3:
//! the prior's pdf, the weight `f cos / pdf` with the glTF BRDF, the albedo
//! `nuld_albedo_brdf`). It reads the blob from a storage buffer that the including shader
//! declares under the name [`BLOB_VARIABLE`], at any group and binding:
//!
//! ```text
//! @group(0) @binding(0) var<storage, read> nuld_blob: array<u32>;
//! ```
//!
//! [`KERNEL_WGSL`], appended to [`WGSL`], makes a complete compute shader (entry
//! point [`KERNEL_ENTRY_POINT`]) that declares that binding itself and fills an
//! output buffer with the samples of a range of (condition, instance, index)
//! described by a [`KernelParams`] uniform. `build-tool shader` translates the two
//! to GLSL, HLSL, MSL and SPIR-V.
//!
//! Validate a blob with [`crate::Blob::parse`] before uploading it: the shader
//! trusts what `parse` checks (on other bytes it stays inside the buffer, as every
//! WGSL array access does, but its values mean nothing).
//!
//! Precision: the functions follow the runtime's `f32` order of operations and
//! port libm's `acosf` and `atanf` (a driver's `acos` and `atan` may be far less
//! accurate); f16 parameters are decoded exactly with integer operations. What
//! remains is the driver's rounding of `sin`, `cos`, `sqrt`, division, `exp` and
//! `atan` (an environment sampler's pdf of a given direction), and its freedom to
//! fuse a multiply and an add
//! (`DirectionSet::direction` maps in `f64`, the shader in `f32`).
//! `tests/tests/shader.rs` holds lavapipe to 8 `f32` ulps of 1.0 in table mode
//! and to `1e-4` in network mode, divided by the warp's local gain for the
//! warps that magnify a rounding of the square point (its docs).
//!
//! [`ConditionalSampler::sample`]: crate::ConditionalSampler::sample
//! [`ConditionalSampler::sample_metallic`]: crate::ConditionalSampler::sample_metallic
//! [`BrdfSampler::sample`]: crate::BrdfSampler::sample
//! [`BrdfSampler::pdf`]: crate::BrdfSampler::pdf
//! [`DirectionSet::direction`]: crate::DirectionSet::direction

use bytemuck::{Pod, Zeroable};

/// The sampling functions (runtime/shaders/nuld.wgsl): WGSL source that expects
/// a module-scope `var<storage, read> nuld_blob: array<u32>` ([`BLOB_VARIABLE`])
/// holding the whole blob.
pub const WGSL: &str = include_str!("../shaders/nuld.wgsl");

/// The sampling kernel (runtime/shaders/nuld_kernel.wgsl): bindings 0 (blob),
/// 1 (output, one `NuldSample` of [`SAMPLE_STRIDE`] bytes per sample: direction
/// `xyz`, weight, pdf) and
/// 2 ([`KernelParams`] uniform) of group 0, and the compute entry point
/// [`KERNEL_ENTRY_POINT`]. Valid WGSL only after [`WGSL`]: use [`kernel_wgsl`].
pub const KERNEL_WGSL: &str = include_str!("../shaders/nuld_kernel.wgsl");

/// The name under which [`WGSL`] reads the blob: the including shader declares
/// `var<storage, read> nuld_blob: array<u32>;` at a group and binding of its choice.
pub const BLOB_VARIABLE: &str = "nuld_blob";

/// The compute entry point of [`KERNEL_WGSL`].
pub const KERNEL_ENTRY_POINT: &str = "nuld_fill";

/// Invocations per workgroup of [`KERNEL_ENTRY_POINT`]: dispatch
/// `ceil(KernelParams::sample_count() / KERNEL_WORKGROUP_SIZE)` workgroups.
pub const KERNEL_WORKGROUP_SIZE: u32 = 64;

/// Workgroups per dispatch dimension that every WebGPU and Vulkan device accepts.
pub const MAX_WORKGROUPS_PER_DIMENSION: u32 = 65_535;

/// Bytes per sample in the kernel's output buffer (`vec3<f32>` direction, `f32`
/// weight, `f32` pdf, padded to the struct's 16-byte alignment, std430).
pub const SAMPLE_STRIDE: u64 = 32;

/// The complete kernel module, [`WGSL`] then [`KERNEL_WGSL`], as one string.
///
/// ```
/// let src = nuld_runtime::shader::kernel_wgsl();
/// assert!(src.contains("fn nuld_sample(") && src.contains("fn nuld_fill("));
/// ```
pub fn kernel_wgsl() -> &'static str {
    KERNEL_SOURCE
}

const KERNEL_SOURCE: &str = concat!(
    include_str!("../shaders/nuld.wgsl"),
    "\n",
    include_str!("../shaders/nuld_kernel.wgsl")
);

/// What the kernel computes per sample of a conditional blob ([`KernelParams::mode`]),
/// at the metallic `KernelParams::view[3]` (read by BRDF samplers on the tabulated
/// prior, [`nuld_core::conditional::PointWarp::BrdfTable`]; the plain modes are the
/// `_metallic` functions, `nuld_sample_metallic` for `nuld_sample` and so on).
/// Point and direction set blobs ignore it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum KernelMode {
    /// `nuld_sample`: table mode at the condition ([`crate::ConditionalSampler::sample`]).
    Table = 0,
    /// `nuld_sample_network` ([`crate::NetworkSampler::sample`]).
    Network = 1,
    /// `nuld_sample_brdf` at [`KernelParams::view`] with roughness = the
    /// condition's first coordinate ([`crate::BrdfSampler::sample`]).
    BrdfTable = 2,
    /// `nuld_sample_brdf_network`
    /// ([`crate::BrdfNetwork::sample`]).
    BrdfNetwork = 3,
    /// `nuld_sample_randomized` with seed = the sample's position `e` in the range
    /// ([`crate::ConditionalSampler::sample_randomized`]).
    TableRandomized = 4,
    /// `nuld_sample_network_randomized` with seed `e`
    /// ([`crate::NetworkSampler::sample_randomized`]).
    NetworkRandomized = 5,
    /// `nuld_sample_metallic`, its pdf replaced by `nuld_pdf_metallic` at its
    /// direction ([`crate::ConditionalSampler::pdf_metallic`]) and its weight by
    /// `nuld_albedo` ([`crate::ConditionalSampler::albedo`]; the weight itself
    /// except for BRDF samplers on the tabulated prior).
    Pdf = 6,
    /// `nuld_sample_brdf_randomized` at [`KernelParams::view`] with seed `e`
    /// ([`crate::BrdfSampler::sample_randomized`]).
    BrdfTableRandomized = 7,
    /// `nuld_sample_brdf_network_randomized` with seed `e`
    /// ([`crate::BrdfNetwork::sample_randomized`]).
    BrdfNetworkRandomized = 8,
    /// `nuld_sample_brdf`, its pdf replaced by `nuld_pdf_brdf` at its direction
    /// ([`crate::BrdfSampler::pdf`]) and its weight by `nuld_albedo_brdf`
    /// ([`crate::BrdfSampler::albedo`]).
    BrdfPdf = 9,
}

/// The kernel's uniform (binding 2; WGSL `NuldKernelParams`, 64 bytes, the same
/// byte offsets): the range of samples to fill.
///
/// Sample `e` is condition `(cx, cy)`, instance `k`, index `i` with
/// `e = ((cy cond_count[0] + cx) instance_count + k) index_count + i`; condition
/// `cond_first + (cx, cy) * cond_step` (computed in `f32` by the shader; a driver
/// may fuse the multiply and the add), instance `instance_first + k`, index
/// `index_first + i`. For a direction set the instance is the set (point sets
/// likewise, written as `(x, y, 0)`), with weight 1.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct KernelParams {
    /// The first condition (blob units).
    pub cond_first: [f32; 2],
    /// Step between consecutive conditions, per axis.
    pub cond_step: [f32; 2],
    /// Conditions per axis.
    pub cond_count: [u32; 2],
    /// The first instance (wrapping `u32`).
    pub instance_first: u32,
    /// Instances per condition.
    pub instance_count: u32,
    /// The first index (wrapping `u32`).
    pub index_first: u32,
    /// Indices per instance.
    pub index_count: u32,
    /// A [`KernelMode`] code.
    pub mode: u32,
    /// Zero (padding).
    pub reserved: u32,
    /// The view `wo` (`xyz`, local frame, any length) of the BRDF modes, and the
    /// metallic (`w`) of every conditional mode (0 from [`Self::new`]).
    pub view: [f32; 4],
}

impl KernelParams {
    /// Samples in the range: `cond_count[0] cond_count[1] instance_count
    /// index_count` (`None` on u32 overflow, which the kernel cannot index).
    ///
    /// ```
    /// use nuld_runtime::shader::{KernelMode, KernelParams};
    /// let p = KernelParams::new(KernelMode::Table, [0.5, 30.0], [0.0; 2], [1, 1], 0..4, 0..64);
    /// assert_eq!(p.sample_count(), Some(256));
    /// ```
    pub fn sample_count(&self) -> Option<u32> {
        self.cond_count[0]
            .checked_mul(self.cond_count[1])?
            .checked_mul(self.instance_count)?
            .checked_mul(self.index_count)
    }

    /// The range `cond_count` conditions from `cond_first` by `cond_step`, the
    /// instances and indices of the two ranges (empty ranges give no samples), in
    /// `mode`, at the view `+z` and metallic 0.
    pub fn new(
        mode: KernelMode,
        cond_first: [f32; 2],
        cond_step: [f32; 2],
        cond_count: [u32; 2],
        instances: core::ops::Range<u32>,
        indices: core::ops::Range<u32>,
    ) -> Self {
        Self {
            cond_first,
            cond_step,
            cond_count,
            instance_first: instances.start,
            instance_count: instances.end.saturating_sub(instances.start),
            index_first: indices.start,
            index_count: indices.end.saturating_sub(indices.start),
            mode: mode as u32,
            reserved: 0,
            view: [0.0, 0.0, 1.0, 0.0],
        }
    }

    /// Workgroups to dispatch, `[x, y, z]`: `g = ceil(count / KERNEL_WORKGROUP_SIZE)`
    /// along x up to [`MAX_WORKGROUPS_PER_DIMENSION`] (WebGPU's and Vulkan's
    /// guaranteed limit), then rows of that many along y; invocations past the
    /// count do nothing. `[0, 1, 1]` for no samples or on overflow.
    ///
    /// ```
    /// use nuld_runtime::shader::{KernelMode, KernelParams};
    /// let p = KernelParams::new(KernelMode::Network, [0.5, 30.0], [0.0; 2], [1, 1], 0..5_000, 0..1_024);
    /// assert_eq!(p.workgroups(), [65_535, 2, 1]); // 80_000 groups of 64
    /// ```
    pub fn workgroups(&self) -> [u32; 3] {
        let groups = self
            .sample_count()
            .map_or(0, |c| c.div_ceil(KERNEL_WORKGROUP_SIZE));
        if groups <= MAX_WORKGROUPS_PER_DIMENSION {
            [groups, 1, 1]
        } else {
            [
                MAX_WORKGROUPS_PER_DIMENSION,
                groups.div_ceil(MAX_WORKGROUPS_PER_DIMENSION),
                1,
            ]
        }
    }
}
