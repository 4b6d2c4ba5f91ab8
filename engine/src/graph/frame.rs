//! The declaration side of the graph: a [`Frame`] is the list of passes one frame runs,
//! each with the resources it touches and how.
//!
//! A compute pass declares each resource once, with the shader variable it binds to
//! ([`Bindings`]): that one list drives the barriers, the byte count the profiler shows
//! and the descriptors [`Frame::add_compute`] binds, so a resource is never named twice.
//! Passes without a shader (uploads, readbacks, the hand-over to presentation, a
//! graphics pass that binds its own attachments) declare plain accesses
//! ([`PassBuilder`]).

use super::access::Access;
use super::context::PassContext;
use super::resources::{Bound, BufferHandle, Extent, ImageHandle, Res};
use crate::error::Result;
use crate::gpu::timestamps::PassOwner;
use crate::gpu::Pipeline;
use crate::shaders::GpuBlock;

type RecordFn<'f> = Box<dyn FnOnce(&mut PassContext) -> Result<()> + 'f>;

/// One declared pass of the frame being built.
pub(crate) struct Pass<'f> {
    pub name: String,
    pub owner: PassOwner,
    pub accesses: Vec<(Res, Access)>,
    /// What the shader variables bind to (passes made by [`Frame::add_compute`]).
    pub bound: Vec<Bound>,
    pub record: Option<RecordFn<'f>>,
}

/// Declares the accesses of a pass that binds no shader variables: transfers and a
/// graphics pass's attachments (compute passes declare [`Bindings`]).
pub struct PassBuilder {
    accesses: Vec<(Res, Access)>,
}

impl PassBuilder {
    pub fn transfer_src(&mut self, h: impl Into<Res>) -> &mut Self {
        self.accesses.push((h.into(), Access::TransferSrc));
        self
    }
    pub fn transfer_dst(&mut self, h: impl Into<Res>) -> &mut Self {
        self.accesses.push((h.into(), Access::TransferDst));
        self
    }
    /// Drawn to by a graphics pipeline (the pass begins and ends its own rendering).
    pub fn color_attachment(&mut self, h: ImageHandle) -> &mut Self {
        self.accesses.push((Res::Image(h), Access::ColorAttachment));
        self
    }
}

/// Declares what a compute pass's shader variables bind to, and so how the pass touches
/// each resource: the variable name is the shader's (`layout(binding = …) … radiance`).
#[derive(Default)]
pub struct Bindings {
    accesses: Vec<(Res, Access)>,
    bound: Vec<Bound>,
}

impl Bindings {
    fn add(&mut self, var: &'static str, res: Res, access: Access, nearest: bool) -> &mut Self {
        self.accesses.push((res, access));
        self.bound.push(Bound { var, res, nearest });
        self
    }
    /// A storage image or buffer the shader reads (`readonly image2D`, `readonly buffer`).
    pub fn read(&mut self, var: &'static str, h: impl Into<Res>) -> &mut Self {
        self.add(var, h.into(), Access::StorageRead, false)
    }
    /// A storage image or buffer the shader writes (previous contents not needed).
    pub fn write(&mut self, var: &'static str, h: impl Into<Res>) -> &mut Self {
        self.add(var, h.into(), Access::StorageWrite, false)
    }
    /// A storage image the shader reads and writes in place (`image2D` without a
    /// qualifier).
    pub fn read_write(&mut self, var: &'static str, h: impl Into<Res>) -> &mut Self {
        self.add(var, h.into(), Access::StorageReadWrite, false)
    }
    /// An image the shader samples with the linear clamp sampler.
    pub fn sampled(&mut self, var: &'static str, h: ImageHandle) -> &mut Self {
        self.add(var, Res::Image(h), Access::Sampled, false)
    }
    /// An image the shader samples with the nearest clamp sampler.
    pub fn sampled_nearest(&mut self, var: &'static str, h: ImageHandle) -> &mut Self {
        self.add(var, Res::Image(h), Access::Sampled, true)
    }
    /// A uniform buffer.
    pub fn uniform(&mut self, var: &'static str, h: BufferHandle) -> &mut Self {
        self.add(var, Res::Buffer(h), Access::Uniform, false)
    }
}

/// The passes of one frame, in submission order.
#[derive(Default)]
pub struct Frame<'f> {
    pub(crate) passes: Vec<Pass<'f>>,
    /// Whom the passes added now work for (see [`Frame::add_owned`]).
    owner: PassOwner,
}

impl<'f> Frame<'f> {
    pub fn new() -> Self {
        Self::default()
    }

    /// Runs `add`, recording every pass it adds as `method`'s own (its timings carry the
    /// owner, so reports total a method's GPU time without reading pass names).
    pub fn add_owned<T>(&mut self, method: &str, add: impl FnOnce(&mut Self) -> T) -> T {
        self.add_for(PassOwner::Method(method.to_string()), add)
    }

    /// Runs `add`, recording every pass it adds as work for `owner` (a pass several
    /// methods need is [`PassOwner::Methods`]: each one's cost includes it).
    pub fn add_for<T>(&mut self, owner: PassOwner, add: impl FnOnce(&mut Self) -> T) -> T {
        let outer = std::mem::replace(&mut self.owner, owner);
        let result = add(self);
        self.owner = outer;
        result
    }

    fn push(
        &mut self,
        name: String,
        accesses: Vec<(Res, Access)>,
        bound: Vec<Bound>,
        record: Option<RecordFn<'f>>,
    ) {
        // A pass that only copies or hands over data is nobody's rendering work.
        let transfer = accesses.iter().all(|(_, a)| {
            matches!(
                a,
                Access::TransferSrc | Access::TransferDst | Access::HostRead | Access::Present
            )
        });
        let owner = if transfer {
            PassOwner::Transfer
        } else {
            self.owner.clone()
        };
        self.passes.push(Pass {
            name,
            owner,
            accesses,
            bound,
            record,
        });
    }

    /// Adds a pass: `declare` lists its accesses, `record` records its commands.
    pub fn add_pass(
        &mut self,
        name: impl Into<String>,
        declare: impl FnOnce(&mut PassBuilder),
        record: impl FnOnce(&mut PassContext) -> Result<()> + 'f,
    ) {
        let mut b = PassBuilder {
            accesses: Vec::new(),
        };
        declare(&mut b);
        self.push(name.into(), b.accesses, Vec::new(), Some(Box::new(record)));
    }

    /// [`Frame::add_pass`] for a copy that stands in for rendering work (a kept march's
    /// history copied forward): it counts for the frame's owner, not as a transfer.
    pub fn add_copy_as_work(
        &mut self,
        name: impl Into<String>,
        declare: impl FnOnce(&mut PassBuilder),
        record: impl FnOnce(&mut PassContext) -> Result<()> + 'f,
    ) {
        let start = self.passes.len();
        self.add_pass(name, declare, record);
        for pass in &mut self.passes[start..] {
            pass.owner = self.owner.clone();
        }
    }

    /// Adds a compute pass: one dispatch of `pipeline` over `grid` invocations (an
    /// [`Extent`] for a full-screen pass; workgroups from the shader's local size), with
    /// `push` as its push constants and every shader variable bound as `declare` says.
    pub fn add_compute<P: GpuBlock>(
        &mut self,
        name: impl Into<String>,
        pipeline: &Pipeline<P>,
        push: P,
        grid: impl Into<[u32; 3]>,
        declare: impl FnOnce(&mut Bindings),
    ) {
        let mut b = Bindings::default();
        declare(&mut b);
        let pipeline = pipeline.clone();
        let groups = pipeline.groups(grid.into());
        let record = move |pc: &mut PassContext| pc.dispatch_bound(&pipeline, &push, groups);
        self.push(name.into(), b.accesses, b.bound, Some(Box::new(record)));
    }

    /// Copies `image` into the host-visible `buffer` and makes it readable by the host:
    /// passes `readback_<label>` (the copy) and `host_read_<label>`.
    pub fn add_readback(&mut self, label: &str, image: ImageHandle, buffer: BufferHandle) {
        self.add_pass(
            format!("readback_{label}"),
            |b| {
                b.transfer_src(image).transfer_dst(buffer);
            },
            move |pc| pc.copy_image_to_buffer(image, buffer),
        );
        self.add_host_read(format!("host_read_{label}"), buffer);
    }

    /// A pass with accesses but no commands: makes a readback visible to the host.
    pub fn add_host_read(&mut self, name: impl Into<String>, buffer: BufferHandle) {
        let accesses = vec![(Res::Buffer(buffer), Access::HostRead)];
        self.push(name.into(), accesses, Vec::new(), None);
    }

    /// A pass with no commands that makes `images` ready for shaders to sample: for
    /// images a frame fills (uploads) that only later frames read, so the graph knows
    /// from their first frame how they will be used.
    pub fn add_ready_for_sampling(&mut self, name: impl Into<String>, images: &[ImageHandle]) {
        let accesses = images
            .iter()
            .map(|&h| (Res::Image(h), Access::Sampled))
            .collect();
        self.push(name.into(), accesses, Vec::new(), None);
    }

    /// A pass with no commands that hands `image` (an imported swapchain image) to the
    /// presentation engine: the graph transitions it to `PRESENT_SRC_KHR`. It must be
    /// the image's last access in the frame.
    pub fn add_present(&mut self, name: impl Into<String>, image: ImageHandle) {
        let accesses = vec![(Res::Image(image), Access::Present)];
        self.push(name.into(), accesses, Vec::new(), None);
    }
}

impl From<Extent> for [u32; 3] {
    fn from(e: Extent) -> Self {
        [e.width, e.height, 1]
    }
}
