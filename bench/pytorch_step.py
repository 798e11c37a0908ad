#!/usr/bin/env python3
"""Speed anchor: one PHNN-JR training step in plain PyTorch vs phnn's stacked step.

What it measures
  PyTorch  One small PHNN-JR model (L_H: MLP 2-16-16-3, L_R: MLP 3-16-16-6,
           tanh), trained with RK2 (h = 0.01), an L1 loss and Adam (lr 1e-3)
           on a batch of 64, in eager mode, float64, one thread. gradH comes
           from torch.autograd.grad(..., create_graph=True). This is the same
           model as bench_training's `baseline` mode. Reported: µs per step,
           timed over 1000 steps after 100 warm-up steps (random data).
  stacked  The same model for 10 members at once, as a skilled PyTorch user
           writes it: weights [E, in, out], every layer one torch.baddbmm
           over the members, one Adam over the stacked tensors; µs per
           member-step = µs per step / 10.
  phnn     The same cell trained by the C++ trainer with 10 members stacked:
           `bench_training run phnn-jr rk2 none STEPS` for STEPS = 200 and
           1200; µs per member-step = (T1200 - T200) / (1000 * 10) * 1e6, so
           data generation, evaluation and inference cancel out.

The three are timed interleaved, `--repeats` times; the table shows the
medians, the ratios to phnn, and the FLOP bound: the multiply-adds of the
step's matrix products (forward with the gradH jet, backward: ~3x the
forward), counted below, at this core's peak of 2 FMA x 4 doubles per cycle
(AVX2/AVX-512 on Zen 4) at --ghz.

How to run (from anywhere; needs Debian's python3-torch and a built
bench_training: cmake --build build --target bench_training)
  /usr/bin/python3 bench/pytorch_step.py [--repeats 3] [--check]
                                         [--binary build/bench_training]
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

import torch

torch.set_default_dtype(torch.float64)
torch.set_num_threads(1)

REPO_ROOT = Path(__file__).resolve().parent.parent
JEMALLOC = Path("/usr/lib/x86_64-linux-gnu/libjemalloc.so.2")
BATCH = 64
H_STEP = 0.01
WARMUP_STEPS = 100
TIMED_STEPS = 1000
MEMBERS = 10
SHORT_STEPS, LONG_STEPS = 200, 1200


# ------------------------------------------------------------------ model
def mlp(n_in, n_out):
    return torch.nn.Sequential(
        torch.nn.Linear(n_in, 16), torch.nn.Tanh(),
        torch.nn.Linear(16, 16), torch.nn.Tanh(),
        torch.nn.Linear(16, n_out))


class PhnnJr(torch.nn.Module):
    """dx/dt = [(J - R(x, u)) (gradH(x), u)]_{1:2}, as bench_training's BaselinePhnnJr."""

    def __init__(self):
        super().__init__()
        self.lh = mlp(2, 3)
        self.lr = mlp(3, 6)
        self.register_buffer("J", torch.tensor([[0.0, 1.0, 0.0],
                                                [-1.0, 0.0, -1.0],
                                                [0.0, 1.0, 0.0]]))
        # Row-major lower triangle: (0,0),(1,0),(1,1),(2,0),(2,1),(2,2).
        self.register_buffer("tril", torch.tril_indices(3, 3))

    def hamiltonian(self, x):
        """H = 1/2 |L_H(x) x|^2, L_H = [[softplus(o0), 0], [o1, softplus(o2)]]."""
        o = self.lh(x)
        q, p = x[:, 0], x[:, 1]
        v0 = torch.nn.functional.softplus(o[:, 0]) * q
        v1 = o[:, 1] * q + torch.nn.functional.softplus(o[:, 2]) * p
        return 0.5 * (v0 * v0 + v1 * v1)

    def grad_h(self, x):
        if not x.requires_grad:
            x = x.detach().requires_grad_(True)
        return torch.autograd.grad(self.hamiltonian(x).sum(), x, create_graph=True)[0]

    def dissipation(self, x, u):
        """R = L^T L, L lower-triangular 3x3 from the 6 outputs of L_R(x, u)."""
        l = self.lr(torch.cat([x, u], dim=-1))
        L = l.new_zeros(l.shape[0], 3, 3)
        L[:, self.tril[0], self.tril[1]] = l
        return L.transpose(1, 2) @ L

    def forward(self, x, u):
        e = torch.cat([self.grad_h(x), u], dim=-1).unsqueeze(-1)
        return ((self.J - self.dissipation(x, u)) @ e).squeeze(-1)[:, :2]


class StackedPhnnJr(torch.nn.Module):
    """PhnnJr for E members at once: layer l is x @ W_l + b_l by baddbmm on [E, B, n]."""

    def __init__(self, members):
        super().__init__()
        self.E = members
        def stack(n_in, n_out):
            sizes = [n_in, 16, 16, n_out]
            ws = torch.nn.ParameterList()
            bs = torch.nn.ParameterList()
            for a, b in zip(sizes[:-1], sizes[1:]):
                bound = 1.0 / a ** 0.5
                ws.append(torch.nn.Parameter(torch.empty(members, a, b).uniform_(-bound, bound)))
                bs.append(torch.nn.Parameter(torch.empty(members, 1, b).uniform_(-bound, bound)))
            return ws, bs
        self.wh, self.bh = stack(2, 3)
        self.wr, self.br = stack(3, 6)
        self.register_buffer("J", torch.tensor([[0.0, 1.0, 0.0],
                                                [-1.0, 0.0, -1.0],
                                                [0.0, 1.0, 0.0]]))
        self.register_buffer("tril", torch.tril_indices(3, 3))

    @staticmethod
    def mlp(ws, bs, x):
        for i, (w, b) in enumerate(zip(ws, bs)):
            x = torch.baddbmm(b, x, w)
            if i + 1 < len(ws):
                x = torch.tanh(x)
        return x

    def hamiltonian(self, x):  # x [E, B, 2]
        o = self.mlp(self.wh, self.bh, x)
        q, p = x[..., 0], x[..., 1]
        v0 = torch.nn.functional.softplus(o[..., 0]) * q
        v1 = o[..., 1] * q + torch.nn.functional.softplus(o[..., 2]) * p
        return 0.5 * (v0 * v0 + v1 * v1)

    def forward(self, x, u):
        if not x.requires_grad:
            x = x.detach().requires_grad_(True)
        g = torch.autograd.grad(self.hamiltonian(x).sum(), x, create_graph=True)[0]
        l = self.mlp(self.wr, self.br, torch.cat([x, u], dim=-1))
        L = l.new_zeros(*l.shape[:2], 3, 3)
        L[..., self.tril[0], self.tril[1]] = l
        e = torch.cat([g, u], dim=-1).unsqueeze(-1)
        return ((self.J - L.transpose(-1, -2) @ L) @ e).squeeze(-1)[..., :2]


def flops_per_member_step():
    """Multiply-adds of one member's step: RK2 = 2 field evaluations; each is
    L_R's forward (B x (3*16 + 16*16 + 16*6)) and L_H's forward with the
    2-direction tangent jet (3 channels: B x 3 x (2*16 + 16*16 + 16*3)); the
    backward costs ~2x the forward (input and weight adjoints). 2 FLOPs each."""
    lr = BATCH * (3 * 16 + 16 * 16 + 16 * 6)
    lh = BATCH * 3 * (2 * 16 + 16 * 16 + 16 * 3)
    return 2 * 2 * (lr + lh) * 3


def rk2(model, x, u, h=H_STEP):
    return x + h * model(x + 0.5 * h * model(x, u), u)


# ------------------------------------------------------------------ PyTorch timing
def random_batch(seed=0):
    g = torch.Generator().manual_seed(seed)
    x = torch.randn(BATCH, 2, generator=g)
    u = torch.randn(BATCH, 1, generator=g)
    x_next = x + 0.01 * torch.randn(BATCH, 2, generator=g)
    return x, u, x_next


def time_steps(step):
    """µs per call of step() over TIMED_STEPS, after WARMUP_STEPS."""
    for _ in range(WARMUP_STEPS):
        step()
    t0 = time.perf_counter()
    for _ in range(TIMED_STEPS):
        step()
    return (time.perf_counter() - t0) / TIMED_STEPS * 1e6


def pytorch_us_per_step(seed):
    """Fresh model and Adam; µs per training step over TIMED_STEPS after warm-up."""
    torch.manual_seed(seed)
    model = PhnnJr()
    adam = torch.optim.Adam(model.parameters(), lr=1e-3)
    x, u, x_next = random_batch()

    def step():
        loss = (x_next - rk2(model, x, u)).abs().mean() / H_STEP
        adam.zero_grad()
        loss.backward()
        adam.step()

    return time_steps(step)


def stacked_us_per_member_step(seed):
    """The stacked model: µs per step over TIMED_STEPS, divided by MEMBERS."""
    torch.manual_seed(seed)
    model = StackedPhnnJr(MEMBERS)
    adam = torch.optim.Adam(model.parameters(), lr=1e-3)
    x, u, x_next = (t.unsqueeze(0).expand(MEMBERS, *t.shape).contiguous() for t in random_batch())

    def step():
        loss = (x_next - rk2(model, x, u)).abs().mean((1, 2)).sum() / H_STEP
        adam.zero_grad()
        loss.backward()
        adam.step()

    return time_steps(step) / MEMBERS


# ------------------------------------------------------------------ gradient check
def grad_h_error(eps=1e-6):
    """Max relative error of autograd gradH against central differences of H."""
    torch.manual_seed(1)
    model = PhnnJr()
    x, _, _ = random_batch(seed=1)
    with torch.no_grad():
        fd = torch.empty_like(x)
        for i in range(x.shape[1]):
            dx = torch.zeros_like(x)
            dx[:, i] = eps
            fd[:, i] = (model.hamiltonian(x + dx) - model.hamiltonian(x - dx)) / (2 * eps)
    g = model.grad_h(x).detach()
    return ((g - fd).abs().max() / g.abs().max()).item()


# ------------------------------------------------------------------ phnn timing
def phnn_environment():
    env = dict(os.environ, OMP_NUM_THREADS="1")
    if JEMALLOC.exists():
        env["LD_PRELOAD"] = str(JEMALLOC)
        return env, f"OMP_NUM_THREADS=1, LD_PRELOAD={JEMALLOC}"
    return env, f"OMP_NUM_THREADS=1, glibc malloc ({JEMALLOC} not found)"


def run_cell_seconds(binary, steps, env):
    cmd = [str(binary), "run", "phnn-jr", "rk2", "none", str(steps)]
    out = subprocess.run(cmd, env=env, capture_output=True, text=True)
    match = re.search(r"([0-9.]+) s\s*$", out.stdout)
    if out.returncode != 0 or match is None:
        sys.exit(f"pytorch_step: '{' '.join(cmd)}' failed (exit {out.returncode}):\n"
                 f"{out.stdout}{out.stderr}")
    return float(match.group(1))


def phnn_us_per_member_step(binary, env):
    t_short = run_cell_seconds(binary, SHORT_STEPS, env)
    t_long = run_cell_seconds(binary, LONG_STEPS, env)
    return (t_long - t_short) / ((LONG_STEPS - SHORT_STEPS) * MEMBERS) * 1e6


# ------------------------------------------------------------------ main
def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3,
                        help="interleaved PyTorch/phnn runs; medians are reported (default 3)")
    parser.add_argument("--binary", type=Path, default=REPO_ROOT / "build" / "bench_training",
                        help="path to bench_training (default: build/bench_training in the repository)")
    parser.add_argument("--ghz", type=float, default=3.7,
                        help="core clock for the FLOP bound (default 3.7, this machine's EPYC)")
    parser.add_argument("--check", action="store_true",
                        help="first verify autograd gradH against central differences of H")
    args = parser.parse_args()
    if args.repeats < 1:
        parser.error("--repeats must be at least 1")
    return args


def main():
    args = parse_args()
    if not args.binary.is_file():
        print(f"pytorch_step: {args.binary} not found; build it with\n"
              f"  cmake --build build --target bench_training", file=sys.stderr)
        return 2

    if args.check:
        err = grad_h_error()
        print(f"gradH check: max relative error vs central differences = {err:.2e}"
              f" ({'ok' if err < 1e-6 else 'FAILED'}, tolerance 1e-6)")
        if err >= 1e-6:
            return 1

    env, setup = phnn_environment()
    print(f"torch {torch.__version__}, float64, {torch.get_num_threads()} thread, eager")
    print(f"phnn set-up: {setup}; binary {args.binary}")

    torch_us, stacked_us, phnn_us = [], [], []
    for r in range(args.repeats):
        torch_us.append(pytorch_us_per_step(seed=r))
        stacked_us.append(stacked_us_per_member_step(seed=r))
        phnn_us.append(phnn_us_per_member_step(args.binary, env))
        print(f"  run {r + 1}/{args.repeats}: PyTorch {torch_us[-1]:.0f} µs/step, "
              f"stacked PyTorch {stacked_us[-1]:.0f} µs/member-step, "
              f"phnn {phnn_us[-1]:.0f} µs/member-step", flush=True)

    t, s, p = (statistics.median(v) for v in (torch_us, stacked_us, phnn_us))
    bound = flops_per_member_step() / (args.ghz * 1e9 * 2 * 2 * 4) * 1e6
    print(f"\nsmall PHNN-JR-RK2, batch {BATCH}, median of {args.repeats} interleaved runs\n")
    print("| implementation | µs per model-step | / phnn |")
    print("|---|---|---|")
    print(f"| PyTorch eager, one model per step | {t:.0f} | {t / p:.1f}x |")
    print(f"| PyTorch eager, {MEMBERS} members stacked (baddbmm) | {s:.0f} | {s / p:.1f}x |")
    print(f"| phnn, {MEMBERS} members stacked | {p:.0f} | 1 |")
    print(f"| FLOP bound ({flops_per_member_step() / 1e6:.2f} MFLOP at {args.ghz} GHz x 16 "
          f"FLOP/cycle) | {bound:.1f} | {bound / p:.2f}x |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
