//! Samples a conditional blob on the GPU with wgpu: the blob's bytes uploaded
//! unchanged as a storage buffer, the WGSL of `nuld_runtime::shader` plus a
//! renderer's compute shader (`shader_sample.wgsl`), the samples read back.
//!
//! `cargo run --release -p nuld-tests --example shader_sample -- BLOB.nuld`
//! (a conditional blob such as `build-tool bake --brdf` writes). Without a file it
//! samples the runtime's small documentation blob.

use nuld_runtime::{AlignedBuf, Blob};
use wgpu::util::DeviceExt;

/// A wgpu device on the first adapter found (any backend wgpu was built with).
pub struct Gpu {
    /// The adapter's name (on lavapipe, "llvmpipe (LLVM ...)").
    pub adapter: String,
    device: wgpu::Device,
    queue: wgpu::Queue,
}

impl Gpu {
    /// The device, or `None` if there is no adapter.
    pub fn new() -> Option<Gpu> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle());
        let adapter =
            pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))
                .ok()?;
        let (device, queue) =
            pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor::default())).ok()?;
        let adapter = adapter.get_info().name;
        Some(Gpu {
            adapter,
            device,
            queue,
        })
    }

    /// The compute pipeline of `entry` in the WGSL `source` (compiled by the driver
    /// once; reuse it across dispatches).
    pub fn pipeline(&self, source: &str, entry: &str) -> wgpu::ComputePipeline {
        let module = self
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: None,
                source: wgpu::ShaderSource::Wgsl(source.into()),
            });
        let desc = wgpu::ComputePipelineDescriptor {
            label: None,
            layout: None,
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        };
        self.device.create_compute_pipeline(&desc)
    }

    /// Runs `pipeline` over `groups` workgroups with the blob at binding 0, an output
    /// of `samples` `vec4<f32>` at binding 1 and, if given, a uniform at binding 2
    /// (all group 0); returns the output and the seconds the dispatch took (the best
    /// of `repeats`, from submission to completion).
    pub fn run(
        &self,
        pipeline: &wgpu::ComputePipeline,
        blob: &[u8],
        uniform: Option<&[u8]>,
        samples: u64,
        groups: [u32; 3],
        repeats: u32,
    ) -> (Vec<[f32; 4]>, f64) {
        let d = &self.device;
        let storage = wgpu::BufferUsages::STORAGE;
        let blob = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("nuld_blob"),
            contents: blob,
            usage: storage,
        });
        let size = samples * 16;
        let out = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("out"),
            size,
            usage: storage | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let read = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("read"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let params = uniform.map(|bytes| {
            d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("params"),
                contents: bytes,
                usage: wgpu::BufferUsages::UNIFORM,
            })
        });
        let mut entries = vec![
            wgpu::BindGroupEntry {
                binding: 0,
                resource: blob.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: out.as_entire_binding(),
            },
        ];
        if let Some(p) = &params {
            entries.push(wgpu::BindGroupEntry {
                binding: 2,
                resource: p.as_entire_binding(),
            });
        }
        let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(0),
            entries: &entries,
        });
        let mut best = f64::INFINITY;
        for _ in 0..repeats.max(1) {
            let mut enc = d.create_command_encoder(&Default::default());
            {
                let mut pass = enc.begin_compute_pass(&Default::default());
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &bind, &[]);
                pass.dispatch_workgroups(groups[0], groups[1], groups[2]);
            }
            let start = std::time::Instant::now();
            self.queue.submit([enc.finish()]);
            d.poll(wgpu::PollType::wait_indefinitely())
                .expect("device lost");
            best = best.min(start.elapsed().as_secs_f64());
        }
        let mut enc = d.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(&out, 0, &read, 0, size);
        self.queue.submit([enc.finish()]);
        read.map_async(wgpu::MapMode::Read, .., |r| r.expect("map the output"));
        d.poll(wgpu::PollType::wait_indefinitely())
            .expect("device lost");
        let view = read.get_mapped_range(..).expect("a mapped output");
        let samples = bytemuck::cast_slice(&view).to_vec();
        (samples, best)
    }
}

#[allow(dead_code)] // the tests include this file for `Gpu` alone
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let bytes = match std::env::args().nth(1) {
        Some(path) => AlignedBuf::read(path)?,
        None => AlignedBuf::from_bytes(&nuld_runtime::doc_example_conditional_blob().0),
    };
    // Validate on the CPU first: the shader trusts what `Blob::parse` checks.
    let n = Blob::parse(bytes.as_bytes())?.conditional()?.len();
    let source = [
        nuld_runtime::shader::WGSL,
        include_str!("shader_sample.wgsl"),
    ]
    .concat();
    let gpu = Gpu::new().ok_or("no GPU adapter (on Linux, install mesa-vulkan-drivers)")?;
    let pixels = 4;
    let samples = pixels * n;
    let groups = [samples.div_ceil(64), 1, 1];
    let pipeline = gpu.pipeline(&source, "main");
    let (out, _) = gpu.run(&pipeline, bytes.as_bytes(), None, samples as u64, groups, 1);
    println!("adapter: {}", gpu.adapter);
    for (e, s) in out.iter().enumerate() {
        println!(
            "pixel {} index {}: direction {:?}, weight {}",
            e as u32 / n,
            e as u32 % n,
            &s[..3],
            s[3]
        );
    }
    Ok(())
}
