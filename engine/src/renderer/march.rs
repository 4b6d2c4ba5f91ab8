//! The features march of a frame: the surface features, or the guide images with the
//! surface features from the same march where a method reads the guides. The march is
//! deterministic, and its inputs are the camera, the medium (TF, cut, time point, label
//! look, brick pool) and the march's own settings; lights are not among them. So a frame
//! whose inputs equal the last march's keeps its images, which still hold that result:
//! only the position history's new side is copied from the old (`features.kept`), and
//! the profile counts the frames the march ran in.

use super::inputs::{CameraMatrices, FrameInputs, LabelLookRef, SeriesTime};
use super::uploads::LutUpload;
use super::Passes;
use crate::error::Result;
use crate::gpu::timestamps::PassOwner;
use crate::gpu::GpuContext;
use crate::graph::{Extent, Frame, ImageHandle, RenderGraph};
use crate::passes::aux_features::AuxFeatures;
use crate::passes::surface_features::FeatureImages;
use crate::passes::SceneBindings;
use crate::scene::Cut;

/// The guide images: (albedo, normal).
pub(super) type GuideImages = (ImageHandle, ImageHandle);

/// Which pass marches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum MarchPass {
    /// The surface features alone (surface_features.comp).
    Surface,
    /// The guide images and the surface features (aux_features.comp), with the normal
    /// guide or without it.
    Guides { normals: bool },
}

/// What a march read: equal keys, equal images.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct MarchKey {
    pass: MarchPass,
    camera: CameraMatrices,
    lut: LutUpload,
    cut: Cut,
    time: Option<SeriesTime>,
    labels: Option<LabelLookRef>,
}

impl MarchKey {
    /// Whether a march of `pass` with `inputs` reads what this one read (compared in
    /// place: the LUT is cloned only when a march runs).
    fn matches(&self, pass: MarchPass, inputs: &FrameInputs) -> bool {
        self.pass == pass
            && self.camera == inputs.camera
            && self.lut == inputs.lut
            && self.cut == inputs.cut
            && self.time == inputs.time
            && self.labels == inputs.labels
    }

    fn new(pass: MarchPass, inputs: &FrameInputs) -> Self {
        Self {
            pass,
            camera: inputs.camera,
            lut: inputs.lut.clone(),
            cut: inputs.cut.clone(),
            time: inputs.time.clone(),
            labels: inputs.labels.clone(),
        }
    }
}

/// The march a frame asks for, and whom it works for.
pub(super) struct MarchRequest {
    pub pass: Option<MarchPass>,
    pub owner: PassOwner,
    /// Whether the surface features are handed on (a method reads them, or they are
    /// read back).
    pub features: bool,
}

/// Adds the march `request` asks for, or keeps the last one's images when `last` (the
/// key of the march that wrote them, `None` after anything that may have changed the
/// medium outside the frame inputs) equals this frame's and they still hold it. Returns
/// the surface features (when handed on) and the guide images (albedo, normal); sets
/// `last` to what the images hold now.
#[allow(clippy::too_many_arguments)]
pub(super) fn add(
    ctx: &GpuContext,
    graph: &mut RenderGraph,
    frame: &mut Frame<'_>,
    passes: &Passes,
    scene: &SceneBindings,
    size: Extent,
    request: MarchRequest,
    inputs: &FrameInputs,
    last: &mut Option<MarchKey>,
) -> Result<(Option<FeatureImages>, Option<GuideImages>)> {
    let Some(pass) = request.pass else {
        *last = None;
        return Ok((None, None));
    };
    let images = FeatureImages::new(ctx, graph, size)?;
    let guides = match pass {
        MarchPass::Guides { .. } => Some(AuxFeatures::images(ctx, graph, size)?),
        MarchPass::Surface => None,
    };
    let position = images.position;
    let held = position.valid
        && [position.prev, images.normal, images.albedo]
            .into_iter()
            .chain(guides.into_iter().flat_map(|(a, n)| [a, n]))
            .all(|h| graph.holds_content(h));
    let features = request.features.then_some(images);
    if held && last.as_ref().is_some_and(|k| k.matches(pass, inputs)) {
        // No pass may touch them this frame: they must not be released as unused.
        for h in [images.normal, images.albedo]
            .into_iter()
            .chain(guides.into_iter().flat_map(|(a, n)| [a, n]))
        {
            graph.retain(h);
        }
        frame.add_for(request.owner, |f| {
            f.add_copy_as_work(
                "features.kept",
                |b| {
                    b.transfer_src(position.prev).transfer_dst(position.cur);
                },
                move |pc| pc.copy_image(position.prev, position.cur),
            )
        });
        return Ok((features, guides));
    }
    *last = Some(MarchKey::new(pass, inputs));
    let guides = frame.add_for(request.owner, |f| match (pass, &passes.aux) {
        (MarchPass::Guides { normals }, Some(aux)) => aux
            .add(ctx, graph, f, scene, size, normals, images)
            .map(Some),
        _ => passes
            .features
            .add(ctx, graph, f, scene, size)
            .map(|_| None),
    })?;
    Ok((features, guides))
}
