//! The device: adapter choice, one shared device and queue per process, compiled kernels.

use std::sync::{Arc, Mutex, OnceLock};

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Floating-point precision on the device (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Precision {
    /// f64 where the adapter offers shader-f64 (Vulkan on most desktop GPUs and on Mesa's
    /// lavapipe), f32 otherwise.
    #[default]
    Auto,
    /// f32: 2^-24 relative round-off; the SOR stops at the round-off plateau of the updates.
    F32,
    /// f64; an error if the adapter lacks shader-f64.
    F64,
}

impl Precision {
    /// Name as on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            Precision::Auto => "auto",
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        }
    }
}

/// What the backend runs on, for reports.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct AdapterReport {
    /// Adapter name, e.g. "NVIDIA H100" or "llvmpipe (LLVM 15.0.6, 256 bits)".
    pub name: String,
    /// Graphics API: vulkan, metal, dx12 or gl.
    pub api: String,
    /// discrete, integrated, virtual, cpu (a software rasteriser) or other.
    pub device_type: String,
    /// Driver name and version.
    pub driver: String,
    /// Whether shaders can use f64.
    pub shader_f64: bool,
}

/// Compiled pipelines of one precision.
pub(crate) struct Kernels {
    pub(crate) layout: wgpu::BindGroupLayout,
    pub(crate) sweep: wgpu::ComputePipeline,
    pub(crate) blocks: wgpu::ComputePipeline,
}

/// (f64 arithmetic, neighbours per node).
type KernelKey = (bool, usize);

/// A device and its queue, shared by all solves of the process.
pub(crate) struct Gpu {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    pub(crate) report: AdapterReport,
    /// Kernels per (precision f64?, stencil size), compiled on first use.
    kernels: Mutex<Vec<(KernelKey, Arc<Kernels>)>>,
}

/// Threads per workgroup of every kernel.
pub(crate) const WORKGROUP: u32 = 256;

/// How to get a software adapter, for the error message.
const HINT: &str = "install a Vulkan driver; without a GPU Mesa's software one works \
(Debian/Ubuntu: `apt-get install mesa-vulkan-drivers libvulkan1`), or use `--backend cpu`. \
WGPU_BACKEND (vulkan, metal, dx12, gl) limits the APIs tried, WGPU_ADAPTER_NAME picks an adapter by name";

static SHARED: OnceLock<std::result::Result<Arc<Gpu>, (String, String)>> = OnceLock::new();

/// The process-wide device, created on first use (the adapter search runs once).
pub(crate) fn shared() -> Result<Arc<Gpu>> {
    SHARED
        .get_or_init(|| Gpu::open().map(Arc::new))
        .clone()
        .map_err(|(tried, reason)| Error::NoGpuAdapter {
            tried,
            reason,
            hint: HINT.to_string(),
        })
}

/// The adapter the wgpu backend uses, or why there is none.
///
/// Adapters are those wgpu finds for the APIs in `WGPU_BACKEND` (default: all); with
/// `WGPU_ADAPTER_NAME` set only adapters whose name contains it (case-insensitive). Among the
/// rest: discrete before integrated before virtual before software GPUs, and any API before GL
/// (its compute support is the weakest).
pub fn gpu_adapter() -> Result<AdapterReport> {
    shared().map(|g| g.report.clone())
}

/// For test suites: whether tests that need the wgpu backend can run here. Without an adapter
/// they are skipped, with one line on stderr per process, unless `HPGE_REQUIRE_GPU=1`: then a
/// missing adapter is a failure (this panics with the reason), as in CI, where Mesa's software
/// Vulkan provides one.
pub fn gpu_test_gate() -> bool {
    static SKIP_NOTE: std::sync::Once = std::sync::Once::new();
    match shared() {
        Ok(_) => true,
        Err(e) if std::env::var("HPGE_REQUIRE_GPU").is_ok_and(|v| v == "1") => {
            panic!("HPGE_REQUIRE_GPU=1 but the wgpu backend is unavailable: {e}")
        }
        Err(e) => {
            SKIP_NOTE.call_once(|| eprintln!("skipping the wgpu tests: {e}"));
            false
        }
    }
}

fn rank(info: &wgpu::AdapterInfo) -> (u8, u8) {
    let ty = match info.device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 3,
        wgpu::DeviceType::Other => 4,
    };
    (ty, u8::from(info.backend == wgpu::Backend::Gl))
}

impl Gpu {
    fn open() -> std::result::Result<Self, (String, String)> {
        let desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        let backends = desc.backends;
        let instance = wgpu::Instance::new(desc);
        let mut adapters = pollster::block_on(instance.enumerate_adapters(backends));
        let found: Vec<String> = adapters
            .iter()
            .map(|a| {
                let i = a.get_info();
                format!("{} ({:?})", i.name, i.backend)
            })
            .collect();
        let apis: Vec<&str> = [
            (wgpu::Backends::VULKAN, "vulkan"),
            (wgpu::Backends::METAL, "metal"),
            (wgpu::Backends::DX12, "dx12"),
            (wgpu::Backends::GL, "gl"),
            (wgpu::Backends::BROWSER_WEBGPU, "webgpu"),
        ]
        .into_iter()
        .filter(|(b, _)| backends.contains(*b))
        .map(|(_, name)| name)
        .collect();
        let tried = format!(
            "APIs tried: {}; adapters found: {}",
            apis.join(", "),
            if found.is_empty() {
                "none".to_string()
            } else {
                found.join(", ")
            }
        );
        let wanted = std::env::var("WGPU_ADAPTER_NAME").ok();
        if let Some(want) = &wanted {
            let want = want.to_lowercase();
            adapters.retain(|a| a.get_info().name.to_lowercase().contains(&want));
        }
        adapters.retain(|a| {
            a.get_downlevel_capabilities()
                .flags
                .contains(wgpu::DownlevelFlags::COMPUTE_SHADERS)
        });
        adapters.sort_by_key(|a| rank(&a.get_info()));
        let Some(adapter) = adapters.into_iter().next() else {
            let reason = match wanted {
                _ if found.is_empty() => "no adapter found".to_string(),
                Some(w) => format!("none with compute shaders matches WGPU_ADAPTER_NAME={w}"),
                None => "none has compute shaders".to_string(),
            };
            return Err((tried, reason));
        };
        let info = adapter.get_info();
        let shader_f64 = adapter.features().contains(wgpu::Features::SHADER_F64);
        let required_features = if shader_f64 {
            wgpu::Features::SHADER_F64
        } else {
            wgpu::Features::empty()
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("hpge-cv"),
            required_features,
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| (tried.clone(), format!("{}: {e}", info.name)))?;
        // Errors are caught by error scopes around every solve; anything else is ignored
        // here instead of wgpu's default panic.
        device.on_uncaptured_error(Arc::new(|e| {
            eprintln!("wgpu: uncaptured error: {e}");
        }));
        let report = AdapterReport {
            name: info.name.clone(),
            api: format!("{:?}", info.backend).to_lowercase(),
            device_type: match info.device_type {
                wgpu::DeviceType::DiscreteGpu => "discrete",
                wgpu::DeviceType::IntegratedGpu => "integrated",
                wgpu::DeviceType::VirtualGpu => "virtual",
                wgpu::DeviceType::Cpu => "cpu",
                wgpu::DeviceType::Other => "other",
            }
            .to_string(),
            driver: format!("{} {}", info.driver, info.driver_info)
                .trim()
                .to_string(),
            shader_f64,
        };
        Ok(Self {
            device,
            queue,
            report,
            kernels: Mutex::new(Vec::new()),
        })
    }

    /// Whether solves at `precision` run in f64 (an error for F64 without shader-f64).
    pub(crate) fn use_f64(&self, precision: Precision) -> Result<bool> {
        match precision {
            Precision::Auto => Ok(self.report.shader_f64),
            Precision::F32 => Ok(false),
            Precision::F64 if self.report.shader_f64 => Ok(true),
            Precision::F64 => Err(Error::Gpu {
                message: format!(
                    "precision f64 asked for, but adapter `{}` has no shader-f64; use f32 or auto",
                    self.report.name
                ),
            }),
        }
    }

    /// The kernels for a precision and stencil size (compiled once).
    pub(crate) fn kernels(&self, f64: bool, stencil: usize) -> Result<Arc<Kernels>> {
        let mut cache = self.kernels.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, k)) = cache.iter().find(|(key, _)| *key == (f64, stencil)) {
            return Ok(k.clone());
        }
        let k = Arc::new(self.compile(f64, stencil)?);
        cache.push(((f64, stencil), k.clone()));
        Ok(k)
    }

    fn compile(&self, f64: bool, stencil: usize) -> Result<Kernels> {
        let real = if f64 { "f64" } else { "f32" };
        let source = include_str!("sor.wgsl")
            .replace("REAL", real)
            .replace("STENCIL", &format!("{stencil}u"))
            .replace("WG", &format!("{WORKGROUP}u"));
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = self
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("sor.wgsl"),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            });
        let entry = |binding: u32, ty: wgpu::BufferBindingType| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let storage = |read_only| wgpu::BufferBindingType::Storage { read_only };
        let layout = self
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("sor"),
                entries: &[
                    entry(0, wgpu::BufferBindingType::Uniform),
                    entry(1, storage(false)),
                    entry(2, storage(true)),
                    entry(3, storage(true)),
                    entry(4, storage(true)),
                    entry(5, storage(true)),
                    entry(6, storage(false)),
                ],
            });
        let pipeline_layout = self
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("sor"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
        let pipeline = |entry: &str| {
            self.device
                .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(entry),
                    layout: Some(&pipeline_layout),
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    cache: None,
                })
        };
        let sweep = pipeline("sweep");
        let blocks = pipeline("blocks");
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::Gpu {
                message: format!("compiling the SOR kernels ({real}): {e}"),
            });
        }
        Ok(Kernels {
            layout,
            sweep,
            blocks,
        })
    }
}
