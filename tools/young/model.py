"""A single-frame estimate for young pixels: a small dilated-convolution network reads the
noisy frame and its guides and predicts, per pixel, the weights of an à-trous cascade of
3×3 kernels (dilations 1, 2, 4, 8) applied to the noisy radiance itself. The output is
always a convex combination of the input's pixels (no colour the frame did not hold),
which is what lets a network this small train on a few hundred frames.

Inputs per pixel: log1p(noisy rgb), the TF albedo and the gradient normal composited
along the ray (the guides OIDN takes: `render(aux=True)`, `dvr eval --aux`); fused, also
log1p of ours' own estimate, which one more output's sigmoid weighs against the
network's. Multiply-adds per output pixel: the weights' count (a quarter of it with the
trunk at half resolution).
"""
import torch
import torch.nn as nn
import torch.nn.functional as F

SLOPE = 0.1
DILATIONS = (1, 2, 4, 8)
OFFSETS = [(dy, dx) for dy in (-1, 0, 1) for dx in (-1, 0, 1)]


def features(noisy, albedo, normal):
    """(N,3,H,W) each -> (N,9,H,W) network input."""
    return torch.cat([torch.log1p(noisy.clamp(min=0.0)), albedo.clamp(0.0, 1.0), normal.clamp(-1.0, 1.0)], 1)


def shift(x, dy, dx):
    """x[p + (dy, dx)], edges clamped (the engine's clamp-to-edge reads)."""
    if dy == 0 and dx == 0:
        return x
    H, W = x.shape[-2:]
    p = max(abs(dy), abs(dx))
    xp = F.pad(x, (p, p, p, p), mode="replicate")
    return xp[..., p + dy : p + dy + H, p + dx : p + dx + W]


class Young(nn.Module):
    def __init__(self, width=24, dilations=(1, 2, 4, 8, 1), levels=DILATIONS, half=False, demod=0.0, fuse=False):
        super().__init__()
        # fuse: the network also reads ours' spatial estimate and predicts, per pixel, how
        # much of its own estimate replaces ours' (a sigmoid of one more output).
        self.fuse = fuse
        # demod > 0: the kernels filter radiance / (albedo + demod) and the result is
        # multiplied back, so the guide albedo's texture is kept rather than averaged.
        self.demod = demod
        self.levels = tuple(levels)
        # half: the trunk runs on 2×2-averaged features (a quarter of the cost) and its
        # kernels are upsampled to the full frame, where they are applied.
        self.half = half
        layers, cin = [], 12 if fuse else 9
        for d in dilations:
            layers.append(nn.Conv2d(cin, width, 3, padding=d, dilation=d, padding_mode="replicate"))
            cin = width
        self.trunk = nn.ModuleList(layers)
        self.head = nn.Conv2d(width, 9 * len(self.levels) + (1 if fuse else 0), 1)

    def kernels(self, x):
        H, W = x.shape[-2:]
        h = F.avg_pool2d(x, 2, ceil_mode=True) if self.half else x
        for conv in self.trunk:
            h = F.leaky_relu(conv(h), SLOPE)
        k = self.head(h)
        return F.interpolate(k, size=(H, W), mode="bilinear", align_corners=False) if self.half else k

    def forward(self, noisy, albedo, normal, ours=None):
        return self.estimates(noisy, albedo, normal, ours)[0]

    def estimates(self, noisy, albedo, normal, ours=None):
        """(the output, the network's own estimate before any fusion)."""
        x = features(noisy, albedo, normal)
        if self.fuse:
            x = torch.cat([x, torch.log1p(ours.clamp(min=0.0))], 1)
        logits = self.kernels(x)
        y = noisy.clamp(min=0.0)
        if self.demod > 0.0:
            a = albedo.clamp(0.0, 1.0) + self.demod
            y = y / a
        for l, d in enumerate(self.levels):
            w = torch.softmax(logits[:, 9 * l : 9 * l + 9], 1)
            y = sum(w[:, k : k + 1] * shift(y, dy * d, dx * d) for k, (dy, dx) in enumerate(OFFSETS))
        y = y * a if self.demod > 0.0 else y
        if not self.fuse:
            return y, y
        c = torch.sigmoid(logits[:, -1:])
        return c * y + (1.0 - c) * ours.clamp(min=0.0), y


def tonemap(x):
    """dvr's display tone map (engine/metrics/src/tonemap.rs): ACES (Narkowicz) then sRGB."""
    x = x.clamp(min=0.0)
    y = (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)
    y = y.clamp(0.0, 1.0)
    return torch.where(y <= 0.0031308, 12.92 * y, 1.055 * y.clamp(min=1e-8) ** (1 / 2.4) - 0.055)


def psnr(a, b):
    """PSNR of two tone-mapped images (peak 1), as dvr's metrics score them."""
    mse = torch.mean((a - b) ** 2)
    return float(10 * torch.log10(1.0 / mse.clamp(min=1e-12)))
