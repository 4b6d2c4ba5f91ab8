"""The recurrent denoising autoencoder (Chaitanya et al. 2017) as dvr runs it.

This file is the single definition of the network, shared by training (train.py), the
weight export (the engine's layout) and the agreement fixture (fixture.py). The engine
mirror is engine/src/denoise/rae.rs + shaders/glsl/rae_*.comp; keep them in step.

Architecture (L = len(widths) - 1 encoder levels, widths[L] the bottleneck):
  x0 = log1p(max(hdr, 0))                      (3 channels, replicate-padded to 2^L)
  level l < L:  a_l = lrelu(conv3x3(x_l))                    enc{l}.feat
                h_l = lrelu(conv3x3(concat(a_l, h_l_prev)))   enc{l}.rec (recurrent state)
                x_{l+1} = maxpool2x2(h_l)
  bottleneck:   d_L = lrelu(conv3x3(x_L))                    bottleneck
  level l < L:  d_l = lrelu(conv3x3(concat(up2(d_{l+1}), h_l)))  dec{l}
  output:       y = conv3x3(d_0) (linear), hdr = expm1(max(y, 0)), cropped
All convolutions are 3x3 with zero padding; lrelu slope 0.1; up2 is nearest-neighbour.
"""
import json
import math

import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F

SLOPE = 0.1
IN_CH = 3


def groups(c):
    return (c + 3) // 4


def layer_specs(widths):
    """(name, in_a, in_b, out) per conv in dispatch and file order."""
    L = len(widths) - 1
    specs = []
    for l in range(L):
        cin = IN_CH if l == 0 else widths[l - 1]
        specs.append((f"enc{l}.feat", cin, 0, widths[l]))
        specs.append((f"enc{l}.rec", widths[l], widths[l], widths[l]))
    specs.append(("bottleneck", widths[L - 1], 0, widths[L]))
    for l in reversed(range(L)):
        specs.append((f"dec{l}", widths[l + 1], widths[l], widths[l]))
    specs.append(("out", widths[0], 0, IN_CH))
    return specs


class Rae(nn.Module):
    def __init__(self, widths):
        super().__init__()
        self.widths = list(widths)
        self.L = len(widths) - 1
        self.convs = nn.ModuleDict()
        for name, a, b, o in layer_specs(self.widths):
            self.convs[name.replace(".", "_")] = nn.Conv2d(a + b, o, 3, padding=1)

    def conv(self, name, x):
        return self.convs[name.replace(".", "_")](x)

    def init_state(self, n, h, w, device=None):
        return [torch.zeros(n, self.widths[l], h >> l, w >> l, device=device) for l in range(self.L)]

    def step(self, x, state):
        """One frame: x (N,3,H,W) already normalised, H and W divisible by 2^L."""
        hs = []
        cur = x
        for l in range(self.L):
            a = F.leaky_relu(self.conv(f"enc{l}.feat", cur), SLOPE)
            h = F.leaky_relu(self.conv(f"enc{l}.rec", torch.cat([a, state[l]], 1)), SLOPE)
            hs.append(h)
            cur = F.max_pool2d(h, 2)
        d = F.leaky_relu(self.conv("bottleneck", cur), SLOPE)
        for l in reversed(range(self.L)):
            up = F.interpolate(d, scale_factor=2, mode="nearest")
            d = F.leaky_relu(self.conv(f"dec{l}", torch.cat([up, hs[l]], 1)), SLOPE)
        return self.conv("out", d), hs


def normalise(hdr):
    return torch.log1p(torch.clamp(hdr, min=0.0))


def denormalise(y):
    return torch.expm1(torch.clamp(y, min=0.0))


def pad_to(x, mult):
    h, w = x.shape[-2:]
    ph = (-h) % mult
    pw = (-w) % mult
    if ph or pw:
        x = F.pad(x, (0, pw, 0, ph), mode="replicate")
    return x


def run_clip(model, frames):
    """frames: (T,3,H,W) HDR tensor -> (T,3,H,W) HDR output, as the engine computes it."""
    T, _, H, W = frames.shape
    mult = 1 << model.L
    out = []
    state = None
    with torch.no_grad():
        for t in range(T):
            x = pad_to(normalise(frames[t : t + 1]), mult)
            if state is None:
                state = model.init_state(1, x.shape[2], x.shape[3])
            y, state = model.step(x, state)
            out.append(denormalise(y)[:, :, :H, :W])
    return torch.cat(out, 0)


def export_floats(model):
    """The engine's weight layout: per conv, for each output group go, input group gi
    (A's groups then B's, each padded to 4 channels), tap t = ky*3+kx, input channel
    c in the group: a vec4 over the group's 4 output channels; then the biases as Gout
    vec4. Returns (flat float32 array, per-layer list of dicts)."""
    chunks = []
    layers = []
    offset = 0
    for name, a, b, o in layer_specs(model.widths):
        conv = model.convs[name.replace(".", "_")]
        w = conv.weight.detach().double().numpy()  # (o, a+b, 3, 3)
        bias = conv.bias.detach().double().numpy()
        ga, gb, go = groups(a), groups(b), groups(o)
        gin = ga + gb
        arr = np.zeros((go, gin, 9, 4, 4), dtype=np.float64)  # [go][gi][t][c][r]
        for ci in range(a + b):
            if ci < a:
                gi, c = ci // 4, ci % 4
            else:
                gi, c = ga + (ci - a) // 4, (ci - a) % 4
            for co in range(o):
                arr[co // 4, gi, :, c, co % 4] = w[co, ci].reshape(9)
        bvec = np.zeros(go * 4)
        bvec[:o] = bias
        layers.append(
            {"name": name, "in_a": a, "in_b": b, "out": o, "weights_offset": offset,
             "bias_offset": offset + arr.size}
        )
        chunks.append(arr.reshape(-1))
        chunks.append(bvec)
        offset += arr.size + bvec.size
    return np.concatenate(chunks).astype("<f4"), layers


def param_count(model):
    return sum(p.numel() for p in model.parameters())


def save(model, bin_path, manifest_path, extra):
    floats, layers = export_floats(model)
    floats.tofile(bin_path)
    manifest = {
        "format": "dvr-rae-1",
        "architecture": "rae-unet",
        "widths": model.widths,
        "in_channels": IN_CH,
        "leaky_relu_slope": SLOPE,
        "input_transform": "log1p(max(rgb, 0)), replicate-padded to a multiple of 2^levels",
        "output_transform": "expm1(max(y, 0)), cropped",
        "weights": bin_path.split("/")[-1],
        "floats": int(floats.size),
        "parameters": param_count(model),
        "layers": layers,
    }
    manifest.update(extra)
    with open(manifest_path, "w") as f:
        json.dump(manifest, f, indent=2)
        f.write("\n")
    return manifest


def load(manifest_path):
    """Rebuilds the torch model from a shipped manifest + .bin (inverse of export)."""
    import os
    with open(manifest_path) as f:
        m = json.load(f)
    model = Rae(m["widths"])
    floats = np.fromfile(os.path.join(os.path.dirname(manifest_path), m["weights"]), dtype="<f4")
    assert floats.size == m["floats"], "weight file size"
    for name, a, b, o in layer_specs(model.widths):
        lay = next(x for x in m["layers"] if x["name"] == name)
        ga, gb, go = groups(a), groups(b), groups(o)
        gin = ga + gb
        n = go * gin * 9 * 16
        arr = floats[lay["weights_offset"] : lay["weights_offset"] + n].reshape(go, gin, 9, 4, 4)
        w = np.zeros((o, a + b, 9), dtype=np.float32)
        for ci in range(a + b):
            gi, c = (ci // 4, ci % 4) if ci < a else (ga + (ci - a) // 4, (ci - a) % 4)
            for co in range(o):
                w[co, ci] = arr[co // 4, gi, :, c, co % 4]
        conv = model.convs[name.replace(".", "_")]
        conv.weight.data = torch.from_numpy(w.reshape(o, a + b, 3, 3).copy())
        conv.bias.data = torch.from_numpy(floats[lay["bias_offset"] : lay["bias_offset"] + o].copy())
    return model, m
