//! The `wgpu` backend: the WGSL kernels of [`steradian_core::wgsl`] on a GPU adapter.
//!
//! One [`Gpu`] holds a device, the compute pipelines (compiled on first use and cached),
//! the cap-exponent table (uploaded once) and the input, output and read-back buffers,
//! which are reused across runs and only grow. A run uploads the batch, dispatches
//! `ceil(n/64)` workgroups folded into a 2-D grid (at most
//! `max_compute_workgroups_per_dimension` along x), copies the output into a mappable
//! staging buffer and reads it back: the timing of a run is a full round trip.
//!
//! Batches larger than the device allows in one binding (`max_storage_buffer_binding_size`,
//! `max_buffer_size`) or than [`Gpu::set_max_chunk_rows`] are split into chunks of
//! contiguous rows; since batches are column-major, each column's slice of the chunk is
//! written to its place in the (chunk-sized, column-major) input buffer.
//!
//! Device errors (validation, out of memory, lost device, failed mapping) are caught with
//! error scopes and returned as [`BackendError`]; nothing panics. The kernels are specified
//! for finite inputs only (see [`steradian_core::wgsl`]).

use std::collections::HashMap;
use std::num::NonZeroU64;
use std::sync::{Arc, Mutex, mpsc};

use super::{Backend, BackendError, check_shapes};
use crate::kernels::{Columns, Kernel};

/// Threads per workgroup of every kernel (`@workgroup_size(64)`).
pub const WORKGROUP_SIZE: u32 = 64;

/// Upper bound on the bytes of one chunk's input or output buffer, whatever the device
/// allows: keeps the buffers (and the driver's staging copies) a reasonable size.
const MAX_CHUNK_BYTES: u64 = 256 << 20;

/// Whether the GPU tests must run: `STERADIAN_REQUIRE_GPU=1` in the environment.
pub fn gpu_required() -> bool {
    std::env::var("STERADIAN_REQUIRE_GPU").is_ok_and(|v| v.trim() == "1")
}

/// [`Gpu::new`], for the report and the tests: `Err` says why no GPU backend is available.
pub fn try_gpu() -> Result<Gpu, String> {
    Gpu::new()
}

/// The adapter when `wanted`, with the note a report prints: the adapter's description,
/// `not requested`, or `no adapter: why`.
pub fn if_requested(wanted: bool) -> (Option<Gpu>, String) {
    if !wanted {
        return (None, "not requested".to_string());
    }
    match try_gpu() {
        Ok(g) => {
            let note = g.adapter_info();
            (Some(g), note)
        }
        Err(e) => (None, format!("no adapter: {e}")),
    }
}

/// The uniform block of every kernel (`struct Params` in the WGSL sources).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    /// Rows in this dispatch.
    n: u32,
    /// Threads per row of the 2-D dispatch: `i = gid.x + gid.y * row_stride`.
    row_stride: u32,
    _pad0: u32,
    _pad1: u32,
}

/// A reusable device buffer that grows on demand.
struct Slot {
    usage: wgpu::BufferUsages,
    label: &'static str,
    buffer: Option<wgpu::Buffer>,
}

impl Slot {
    fn new(label: &'static str, usage: wgpu::BufferUsages) -> Self {
        Slot {
            usage,
            label,
            buffer: None,
        }
    }

    /// A buffer of at least `size` bytes (`size > 0`, a multiple of 4).
    fn get(&mut self, device: &wgpu::Device, size: u64) -> &wgpu::Buffer {
        if self.buffer.as_ref().is_none_or(|b| b.size() < size) {
            if let Some(old) = self.buffer.take() {
                old.destroy();
            }
            self.buffer = Some(device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(self.label),
                size,
                usage: self.usage,
                mapped_at_creation: false,
            }));
        }
        self.buffer.as_ref().expect("just created")
    }
}

/// The `wgpu` backend. See the module docs.
pub struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    layout: wgpu::BindGroupLayout,
    layout_table: wgpu::BindGroupLayout,
    pipelines: HashMap<(&'static str, usize, usize), wgpu::ComputePipeline>,
    params: wgpu::Buffer,
    table: wgpu::Buffer,
    /// The caller's table of a [`Custom`] kernel.
    user_table: Slot,
    input: Slot,
    output: Slot,
    staging: Slot,
    /// Largest byte size of one input or output buffer.
    max_chunk_bytes: u64,
    /// Largest workgroup count per dispatch dimension.
    max_groups_per_dim: u32,
    /// Optional caller-set cap on the rows of one chunk.
    max_chunk_rows: Option<usize>,
    /// Errors that escaped the error scopes, and device loss, reported asynchronously.
    uncaptured: Arc<Mutex<Vec<String>>>,
}

/// The first `size` bytes of `buffer` as a binding.
fn binding(buffer: &wgpu::Buffer, size: u64) -> wgpu::BindingResource<'_> {
    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
        buffer,
        offset: 0,
        size: NonZeroU64::new(size),
    })
}

fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: NonZeroU64::new(std::mem::size_of::<Params>() as u64),
        },
        count: None,
    }
}

/// Runs `f` inside validation and out-of-memory error scopes; an error caught by either is
/// returned as `BackendError` prefixed with `what`.
fn scoped<T>(device: &wgpu::Device, what: &str, f: impl FnOnce() -> T) -> Result<T, BackendError> {
    let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let value = f();
    let v = pollster::block_on(validation.pop());
    let o = pollster::block_on(oom.pop());
    match v.or(o) {
        Some(e) => Err(BackendError(format!("{what}: {e}"))),
        None => Ok(value),
    }
}

impl Gpu {
    /// Opens the high-performance adapter wgpu finds (any backend: Vulkan, GL, Metal, DX12;
    /// `WGPU_BACKEND` and the other wgpu environment variables are honoured) and a device
    /// with the adapter's limits. `Err` says why not: no adapter, device request failed, …
    pub fn new() -> Result<Gpu, String> {
        // wgpu may panic inside a broken driver stack; report that as "no GPU" instead.
        match std::panic::catch_unwind(Self::open) {
            Ok(r) => r,
            Err(p) => {
                let msg = p
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_else(|| "unknown panic".into());
                Err(format!("wgpu panicked while opening a device: {msg}"))
            }
        }
    }

    fn open() -> Result<Gpu, String> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            apply_limit_buckets: false,
        }))
        .map_err(|e| format!("no GPU adapter: {e}"))?;
        let info = adapter.get_info();
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("steradian"),
            required_features: wgpu::Features::empty(),
            required_limits: limits.clone(),
            ..Default::default()
        }))
        .map_err(|e| format!("device request failed on {}: {e}", info.name))?;

        let uncaptured = Arc::new(Mutex::new(Vec::new()));
        {
            let sink = Arc::clone(&uncaptured);
            device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
                if let Ok(mut v) = sink.lock() {
                    v.push(e.to_string());
                }
            }));
            let sink = Arc::clone(&uncaptured);
            device.set_device_lost_callback(move |reason, msg| {
                if let Ok(mut v) = sink.lock() {
                    v.push(format!("device lost ({reason:?}): {msg}"));
                }
            });
        }

        let max_chunk_bytes = MAX_CHUNK_BYTES
            .min(limits.max_storage_buffer_binding_size)
            .min(limits.max_buffer_size)
            // every index in the shader is a u32
            .min(u32::MAX as u64)
            & !3;
        if max_chunk_bytes < 8 * 4 {
            return Err(format!(
                "{}: storage buffers too small ({} bytes)",
                info.name, max_chunk_bytes
            ));
        }
        let max_groups_per_dim = limits.max_compute_workgroups_per_dimension.max(1);

        let (layout, layout_table, params, table) = scoped(&device, "creating resources", || {
            let base = [
                storage_entry(0, true),
                storage_entry(1, false),
                uniform_entry(2),
            ];
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("steradian kernel"),
                entries: &base,
            });
            let with_table = [base[0], base[1], base[2], storage_entry(3, true)];
            let layout_table = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("steradian kernel with table"),
                entries: &with_table,
            });
            let params = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("steradian params"),
                size: std::mem::size_of::<Params>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let bytes: &[u8] = bytemuck::cast_slice(&steradian_core::lobe::cap::TABLE[..]);
            let table = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("steradian cap-exponent table"),
                size: bytes.len() as u64,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            queue.write_buffer(&table, 0, bytes);
            (layout, layout_table, params, table)
        })
        .map_err(|e| format!("{}: {e}", info.name))?;

        Ok(Gpu {
            device,
            queue,
            info,
            layout,
            layout_table,
            pipelines: HashMap::new(),
            params,
            table,
            input: Slot::new(
                "steradian input",
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            ),
            output: Slot::new(
                "steradian output",
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            ),
            user_table: Slot::new(
                "steradian custom table",
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            ),
            staging: Slot::new(
                "steradian read-back",
                wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            ),
            max_chunk_bytes,
            max_groups_per_dim,
            max_chunk_rows: None,
            uncaptured,
        })
    }

    /// The adapter, e.g. `"llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan, Cpu)"`.
    pub fn adapter_info(&self) -> String {
        format!(
            "{} ({:?}, {:?})",
            self.info.name, self.info.backend, self.info.device_type
        )
    }

    /// Caps the rows of one chunk (`None`: only the device limits split a batch). Useful
    /// to bound memory, and to exercise the chunking in tests. A cap of 0 counts as 1.
    pub fn set_max_chunk_rows(&mut self, max: Option<usize>) {
        self.max_chunk_rows = max.map(|m| m.max(1));
    }

    /// Rows of one chunk for `kernel`: limited by the device's buffer limits, the dispatch
    /// grid and [`Gpu::set_max_chunk_rows`].
    pub fn chunk_rows(&self, kernel: Kernel) -> usize {
        self.chunk_rows_for(kernel.input_arity(), kernel.output_arity())
    }

    fn chunk_rows_for(&self, input_arity: usize, output_arity: usize) -> usize {
        let arity = input_arity.max(output_arity).max(1) as u64;
        let by_bytes = self.max_chunk_bytes / (4 * arity);
        let g = self.max_groups_per_dim as u64;
        let by_grid = g * g * WORKGROUP_SIZE as u64;
        let rows = by_bytes.min(by_grid).max(1);
        let rows = usize::try_from(rows).unwrap_or(usize::MAX);
        self.max_chunk_rows.map_or(rows, |m| rows.min(m))
    }

    /// Fails with the first error reported outside an error scope (or device loss).
    fn take_uncaptured(&self) -> Result<(), BackendError> {
        let mut v = self
            .uncaptured
            .lock()
            .map_err(|_| BackendError("wgpu error sink poisoned".into()))?;
        if v.is_empty() {
            Ok(())
        } else {
            let msg = v.join("; ");
            v.clear();
            Err(BackendError(format!("wgpu: {msg}")))
        }
    }

    /// The pipeline of `job`, compiled on first use.
    fn pipeline(&mut self, job: &Job) -> Result<wgpu::ComputePipeline, BackendError> {
        // Keyed by the label and the source itself (its address and length): two sources
        // under one label are two pipelines.
        let key = (job.label, job.source.as_ptr() as usize, job.source.len());
        if let Some(p) = self.pipelines.get(&key) {
            return Ok(p.clone());
        }
        let (kernel, src) = (job.label, job.source);
        let layout = if job.table.is_some() {
            &self.layout_table
        } else {
            &self.layout
        };
        let device = &self.device;
        let pipeline = scoped(device, &format!("{kernel}: compiling"), || {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(kernel),
                source: wgpu::ShaderSource::Wgsl(src.into()),
            });
            let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(kernel),
                bind_group_layouts: &[Some(layout)],
                immediate_size: 0,
            });
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(kernel),
                layout: Some(&pl),
                module: &module,
                entry_point: Some("main"),
                compilation_options: Default::default(),
                cache: None,
            })
        })?;
        self.take_uncaptured()?;
        self.pipelines.insert(key, pipeline.clone());
        Ok(pipeline)
    }

    /// Runs rows `r0..r0 + rows` of `input` into the same rows of `out`.
    fn run_chunk(
        &mut self,
        job: &Job,
        pipeline: &wgpu::ComputePipeline,
        input: &Columns,
        out: &mut Columns,
        r0: usize,
        rows: usize,
    ) -> Result<(), BackendError> {
        let n = input.n;
        let (kernel, ia, oa) = (job.label, job.input_arity, job.output_arity);
        let in_bytes = (ia * rows * 4) as u64;
        let out_bytes = (oa * rows * 4) as u64;

        // 2-D fold of ceil(rows/64) workgroups: as few rows of the grid as the per-dimension
        // limit allows, each as short as possible so that few threads idle.
        let groups = rows.div_ceil(WORKGROUP_SIZE as usize) as u64;
        let gy = groups.div_ceil(self.max_groups_per_dim as u64);
        let gx = groups.div_ceil(gy);
        let params = Params {
            n: rows as u32,
            row_stride: (gx * WORKGROUP_SIZE as u64) as u32,
            _pad0: 0,
            _pad1: 0,
        };

        let device = self.device.clone();
        let queue = self.queue.clone();
        let buffers = scoped(&device, &format!("{kernel}: allocating buffers"), || {
            (
                self.input.get(&device, in_bytes).clone(),
                self.output.get(&device, out_bytes).clone(),
                self.staging.get(&device, out_bytes).clone(),
            )
        });
        let (in_buf, out_buf, staging) = match buffers {
            Ok(b) => b,
            Err(e) => {
                // Do not keep a buffer whose creation failed.
                self.input.buffer = None;
                self.output.buffer = None;
                self.staging.buffer = None;
                return Err(e);
            }
        };

        let user_table = self.user_table.buffer.clone();
        scoped(&device, &format!("{kernel}: dispatch"), || {
            // Column c of the chunk goes to c·rows in the input buffer (column-major).
            if r0 == 0 && rows == n {
                queue.write_buffer(&in_buf, 0, bytemuck::cast_slice(&input.data[..]));
            } else {
                for c in 0..ia {
                    let col = &input.data[c * n + r0..c * n + r0 + rows];
                    queue.write_buffer(&in_buf, (c * rows * 4) as u64, bytemuck::cast_slice(col));
                }
            }
            queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));

            let mut entries = vec![
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: binding(&in_buf, in_bytes),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: binding(&out_buf, out_bytes),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: self.params.as_entire_binding(),
                },
            ];
            let layout = match job.table {
                None => &self.layout,
                Some(TableSource::CapExponent) => {
                    entries.push(wgpu::BindGroupEntry {
                        binding: 3,
                        resource: self.table.as_entire_binding(),
                    });
                    &self.layout_table
                }
                Some(TableSource::User(bytes)) => {
                    entries.push(wgpu::BindGroupEntry {
                        binding: 3,
                        resource: binding(
                            user_table.as_ref().expect("uploaded before the dispatch"),
                            bytes,
                        ),
                    });
                    &self.layout_table
                }
            };
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(kernel),
                layout,
                entries: &entries,
            });

            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some(kernel),
            });
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(kernel),
                    timestamp_writes: None,
                });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &bind_group, &[]);
                pass.dispatch_workgroups(gx as u32, gy as u32, 1);
            }
            encoder.copy_buffer_to_buffer(&out_buf, 0, &staging, 0, out_bytes);
            queue.submit([encoder.finish()]);
        })?;

        // Read back. On failure the staging buffer is dropped, so that a map still pending
        // cannot spoil the next run.
        let (tx, rx) = mpsc::channel();
        staging.map_async(wgpu::MapMode::Read, 0..out_bytes, move |r| {
            let _ = tx.send(r);
        });
        let mapped = device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| BackendError(format!("{kernel}: waiting for the device: {e}")))
            .and_then(|_| self.take_uncaptured())
            .and_then(|()| match rx.try_recv() {
                Ok(Ok(())) => Ok(()),
                Ok(Err(e)) => Err(BackendError(format!("{kernel}: mapping the output: {e}"))),
                Err(_) => Err(BackendError(format!(
                    "{kernel}: the output was not mapped after waiting for the device"
                ))),
            });
        if let Err(e) = mapped {
            self.staging.buffer = None;
            return Err(e);
        }
        let result = (|| {
            let view = staging
                .get_mapped_range(0..out_bytes)
                .map_err(|e| BackendError(format!("{kernel}: reading the output: {e}")))?;
            for c in 0..oa {
                let dst = &mut out.data[c * n + r0..c * n + r0 + rows];
                let src = &view[c * rows * 4..(c + 1) * rows * 4];
                bytemuck::cast_slice_mut::<f32, u8>(dst).copy_from_slice(src);
            }
            Ok(())
        })();
        staging.unmap();
        result
    }
}

/// Where binding 3 of a job comes from.
#[derive(Clone, Copy, Debug)]
enum TableSource {
    /// The built-in cap-exponent table.
    CapExponent,
    /// The caller's table, this many bytes (already uploaded to `user_table`).
    User(u64),
}

/// One compute job: a complete WGSL source with the batch bindings.
struct Job {
    label: &'static str,
    source: &'static str,
    input_arity: usize,
    output_arity: usize,
    table: Option<TableSource>,
}

/// A WGSL kernel outside [`Kernel`] (lobe products, SAT and VDT queries, RSL shading, …) with
/// the batch bindings of [`steradian_core::wgsl`]: 0 = input columns, 1 = output columns,
/// 2 = `Params`, and 3 = `table`, a read-only `array<f32>` the caller supplies (or none).
#[derive(Clone, Copy, Debug)]
pub struct Custom<'a> {
    /// Pipeline cache key and label; one label per source.
    pub label: &'static str,
    /// The complete WGSL source (prelude included).
    pub source: &'static str,
    /// Binding 3, or `None` for a kernel without it. Uploaded on every call.
    pub table: Option<&'a [f32]>,
}

impl Gpu {
    /// Runs a [`Custom`] kernel: `input.arity` columns in, `out.arity` columns out, `out.n`
    /// must equal `input.n`. Batches are split into chunks as for the built-in kernels.
    pub fn run_custom(
        &mut self,
        custom: &Custom<'_>,
        input: &Columns,
        out: &mut Columns,
    ) -> Result<(), BackendError> {
        if out.n != input.n
            || input.data.len() != input.arity * input.n
            || out.data.len() != out.arity * out.n
        {
            return Err(BackendError(format!(
                "{}: column shapes do not match ({}×{} in, {}×{} out)",
                custom.label, input.arity, input.n, out.arity, out.n
            )));
        }
        let table = match custom.table {
            None => None,
            Some(t) => {
                // An empty storage binding is invalid: bind one zero instead.
                let data: &[f32] = if t.is_empty() { &[0.0] } else { t };
                let bytes = (data.len() * 4) as u64;
                let device = self.device.clone();
                let buf = scoped(&device, &format!("{}: table", custom.label), || {
                    self.user_table.get(&device, bytes).clone()
                })?;
                self.queue.write_buffer(&buf, 0, bytemuck::cast_slice(data));
                Some(TableSource::User(bytes))
            }
        };
        let job = Job {
            label: custom.label,
            source: custom.source,
            input_arity: input.arity,
            output_arity: out.arity,
            table,
        };
        self.run_job(&job, input, out)
    }

    fn run_job(
        &mut self,
        job: &Job,
        input: &Columns,
        out: &mut Columns,
    ) -> Result<(), BackendError> {
        let n = input.n;
        if n == 0 {
            return Ok(());
        }
        let pipeline = self.pipeline(job)?;
        let chunk = self.chunk_rows_for(job.input_arity, job.output_arity);
        let mut r0 = 0;
        while r0 < n {
            let rows = chunk.min(n - r0);
            self.run_chunk(job, &pipeline, input, out, r0, rows)?;
            r0 += rows;
        }
        Ok(())
    }
}

impl Backend for Gpu {
    fn name(&self) -> &'static str {
        "wgpu"
    }

    fn run(
        &mut self,
        kernel: Kernel,
        input: &Columns,
        out: &mut Columns,
    ) -> Result<(), BackendError> {
        check_shapes(kernel, input, out)?;
        let job = Job {
            label: kernel.name(),
            source: crate::registry::of(kernel)
                .wgsl
                .get()
                .map(|w| w.source)
                .ok_or_else(|| BackendError(format!("{kernel}: no WGSL source")))?,
            input_arity: kernel.input_arity(),
            output_arity: kernel.output_arity(),
            table: kernel.spec().cap_table.then_some(TableSource::CapExponent),
        };
        self.run_job(&job, input, out)
    }
}
