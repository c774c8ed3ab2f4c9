#!/usr/bin/env bash
# Regenerates every figure, CSV and JSON of studies/accuracy-cost/README.md (issue 16; spec
# numerics-and-periodic section 9) into studies/accuracy-cost/results/.  Run from the repository root:
#     bash studies/accuracy-cost/run.sh            # all (many hours of one core: the (e) parts dominate)
#     bash studies/accuracy-cost/run.sh chain-S2   # the chain-S2 part only (also chain-A1, band, local, variant-e,
#                                                  # variant-e-4ms, w-short, w-4ms, imex-short, variant-b-4ms,
#                                                  # w-4ms-dumka3, variant-b-4ms-smoothed, w-4ms-smoothed,
#                                                  # imex-all-short, elastic-short: both faces,
#                                                  # elastic-inclined-short, elastic-inclined-4ms,
#                                                  # elastic-inclined-4ms-smoothed, multirate, adaptive)
# Each test-2 run prints its speed-up table (Table 2.4 style); the logs go next to the results.
set -euo pipefail
cd "$(dirname "$0")/../.."
out=studies/accuracy-cost/results
mkdir -p "$out"
cvtfem=${CVTFEM:-.venv/bin/cvtfem}
part=${1:-all}

test2() {  # test2 TAG SCENE ARGS...: spectra with v0 and v0/10, test 2, table
  local tag=$1 scene=$2; shift 2
  nice "$cvtfem" study accuracy-cost "$scene" "$@" \
    --png "$out/$tag.png" --spectrum-png "$out/$tag-spectrum.png" --csv "$out/$tag.csv" --json "$out/$tag.json" \
    | tee "$out/$tag.log"
  uptime | tee -a "$out/$tag.log"
}

for law in linear-saturated smoothed; do
  if [[ $part == all || $part == chain-S2 || $part == "chain-S2-$law" ]]; then
    test2 "chain-S2-$law" "studies/accuracy-cost/scenes/chain-S2-chapter2-$law.toml" \
      --window 1e-3:5e-3 --sample 1e-5 --fixed rk4,dopri45,gbs-smooth:stages=2 --steps 1e-6,2e-6,4e-6 \
      --adaptive Radau,BDF,rodas5p,dopri45,rock4 --rtols 1e-1,1e-2,1e-3 --repeats 1 \
      --reference Radau:1e-7 --check rodas5p:1e-7
  fi
done
if [[ $part == all || $part == chain-A1 ]]; then   # A1 costs ~20x S2 per RHS call: a 2 ms run, one law
  test2 chain-A1-linear-saturated studies/accuracy-cost/scenes/chain-A1-chapter2-linear-saturated.toml \
    --window 1e-3:2e-3 --sample 1e-5 --fixed rk4 --steps 2e-6,4e-6 \
    --adaptive rodas5p,dopri45,rock4 --rtols 1e-2 --repeats 1 --reference Radau:1e-6 --check rodas5p:1e-6
fi
if [[ $part == all || $part == band ]]; then
  test2 band-6+2n band-6+2n,regime-chapter2 --window 1e-3:5e-3 --sample 1e-5 --fixed rk4,dopri45 \
    --steps 5e-8,1e-6,2e-6,5e-6,1e-5 --adaptive Radau,BDF,rodas5p,dopri45,rock4 --rtols 1e-1,1e-2,1e-3 --repeats 3
fi
if [[ $part == all || $part == local ]]; then   # test 1: every playground method, one step from the state at 1 ms
  for law in linear-saturated smoothed; do
    nice "$cvtfem" study accuracy-cost "studies/accuracy-cost/scenes/chain-S2-chapter2-$law.toml" --local \
      --window 1e-3:5e-3 --hs 1e-8:1e-5:13 \
      --local-png "$out/chain-S2-$law-local.png" --local-csv "$out/chain-S2-$law-local.csv" \
      | tee "$out/chain-S2-$law-local.log"
  done
fi

# Variant (e) (A5 + refined contact H2) and (zh) (A5 + H1) on rigid shafts, uniform chain, chapter-2 regime.  The
# quasi-static start stalls there (0.069 / 0.023 of F2 after 151 evaluations, ~100 s), so the runs start placed on
# the sheaves (--placed) and measure E over [1, 3] us after 1 us of settling (the source's 1..5 ms is out of reach at
# today's cost: docs/accuracy-cost.md).  The spectra (two dense eigenvalue problems of 3544 states, 8-10 min each on
# a loaded machine) come from a5_friction_spectra.py.  Once the elastic shafts of (e) run, the same lines with the
# scenes' `shaft_elasticity = false` removed repeat the study on them.
e_scene() { echo "studies/accuracy-cost/scenes/variant-$1-rigid-chapter2-$2.toml"; }
EXPLICIT=euler,rk4,dopri45,dopri56,dopri78,euler-extrapolation,gbs,gbs-smooth,rkc,rock2,rock4,dumka3
IMPLICIT=implicit-euler,theta,trapezoidal,sw24,w1,w1-extrapolation,rodas4,rodas5p,radau5
for law in linear-saturated smoothed; do
  if [[ $part == all || $part == variant-e || $part == "variant-e-$law" ]]; then
    e2() { test2 "$1" "$(e_scene e $law)" --placed --skip-spectrum --window 1e-6:3e-6 --sample 2e-8 --repeats 1 \
             --reference DOP853:1e-7 --check dopri78:1e-7 "${@:2}"; }
    e2 "variant-e-$law" --fixed rk4,dopri45,gbs-smooth:stages=2,dumka3 --steps 1e-8,2e-8,5e-8 \
      --adaptive rock4,dopri45 --rtols 1e-2,1e-3
    e2 "variant-e-$law-large" --fixed rk4,dopri45,gbs-smooth:stages=2,dumka3 --steps 5e-8,1e-7,2e-7,5e-7,1e-6 \
      --adaptive rock4,rodas5p,Radau --rtols 1e-1,1e-2
    test2 "variant-e-$law-10us" "$(e_scene e $law)" --placed --skip-spectrum --window 2e-6:1e-5 --sample 5e-8 \
      --repeats 1 --reference DOP853:1e-6 --check dopri78:1e-6 --fixed rk4,dopri45 --steps 5e-8,2e-7,1e-6,2e-6 \
      --adaptive rock4,rodas5p --rtols 1e-2
    test2 "variant-e-$law-5us" "$(e_scene e $law)" --placed --settle 5e-6 --window 5e-6:7e-6 --sample 1e-7 \
      --repeats 1 --reference DOP853:1e-6 --check dopri78:1e-6 --fixed rk4 --steps 5e-8,1e-6 --adaptive rock4 \
      --rtols 1e-2                             # with the spectra at 5 us (v0 and v0/10)
    for at in 0 1e-6; do                       # test 1 from the placed state and from the state at 1 us
      tag="variant-e-$law-local$([[ $at == 0 ]] || echo 1us)"
      for kind in explicit implicit; do
        methods=$([[ $kind == explicit ]] && echo $EXPLICIT || echo $IMPLICIT)
        nice "$cvtfem" study accuracy-cost "$(e_scene e $law)" --placed --local --local-at $at --window 0:1e-5 \
          --hs 5e-9:2e-7:7 --methods "$methods" --reference DOP853:1e-9 --local-png "$out/$tag-$kind.png" \
          --local-csv "$out/$tag-$kind.csv" | tee "$out/$tag-$kind.log"
      done
    done
  fi
done
# Test 2 of variant (e) over the source's window, E over [1, 5] ms (session 9): from the placement (the quasi-static
# start at ratio 0.45 needs more lifted Newton iterations than static_balance allows: docs/accuracy-cost.md).  The runs
# are kept in a cache directory, so the parts below may run in parallel (two shells sharing the directory) or be
# resumed; the last call tabulates every run the cache holds and the force-trace script redraws the output.
if [[ $part == all || $part == variant-e-4ms ]]; then
  cache=out/studies/variant-e-4ms-cache   # reference outputs (npy, 5 MB each) and rows (not kept in git); delete to re-measure
  e4() { nice "$cvtfem" study accuracy-cost "$(e_scene e linear-saturated)" --placed --skip-spectrum \
           --window 1e-3:5e-3 --sample 1e-6 --repeats 1 --reference DOP853:1e-6 --check dopri78:1e-6 --cache "$cache" \
           --png "$out/variant-e-4ms.png" --csv "$out/variant-e-4ms.csv" --json "$out/variant-e-4ms.json" "$@"; }
  e4 --fixed rk4,dopri45 --steps 5e-7,1e-6,2e-6 --adaptive rock4,dopri45 --rtols 1e-2,1e-3
  e4 --fixed rk4 --steps 2e-7,5e-8 --adaptive ""
  e4 --fixed dumka3 --steps 1e-6,2e-6 --adaptive ""
  e4 --from-cache | tee "$out/variant-e-4ms.log"
  uptime | tee -a "$out/variant-e-4ms.log"
  nice .venv/bin/python studies/accuracy-cost/force_trace.py "$out/variant-e-4ms.json" "$cache" rk4:1e-6,rk4:2e-6 \
    "$out/variant-e-4ms-trace.png" | tee -a "$out/variant-e-4ms.log"
fi
# Session 11: variant (b) itself (chain A1, refined contact H2, ELASTIC shafts: the scene as the preset builds it),
# chapter-2 regime, E over the source's [1, 5] ms from the quasi-static start, with its spectrum at the start.
if [[ $part == all || $part == variant-b-4ms ]]; then
  cache=out/studies/variant-b-4ms-cache
  b4() { nice "$cvtfem" study accuracy-cost studies/accuracy-cost/scenes/variant-b-chapter2-linear-saturated.toml \
           --window 1e-3:5e-3 --sample 1e-6 --repeats 1 --reference DOP853:1e-6 --check dopri78:1e-6 --cache "$cache" \
           --png "$out/variant-b-4ms.png" --csv "$out/variant-b-4ms.csv" --json "$out/variant-b-4ms.json" "$@"; }
  b4 --fixed rk4 --steps 5e-8 --adaptive "" --spectrum-png "$out/variant-b-4ms-spectrum.png"
  b4 --skip-spectrum --fixed rk4,dumka3 --steps 5e-7,1e-6,2e-6 --adaptive rock4,dumka3,dopri45 --rtols 1e-1,1e-2,1e-3
  b4 --skip-spectrum --fixed "" --adaptive dumka3 --rtols 3e-2          # the preset's default since session 11
  b4 --skip-spectrum --from-cache | tee "$out/variant-b-4ms.log"
  uptime | tee -a "$out/variant-b-4ms.log"
fi
# Session 12: variant (b) with the smoothed pin-sheave friction law (C1 at v0), the same protocol as variant-b-4ms.
if [[ $part == all || $part == variant-b-4ms-smoothed ]]; then
  cache=out/studies/variant-b-4ms-smoothed-cache
  bs() { nice "$cvtfem" study accuracy-cost studies/accuracy-cost/scenes/variant-b-chapter2-smoothed.toml \
           --window 1e-3:5e-3 --sample 1e-6 --repeats 1 --reference DOP853:1e-6 --check dopri78:1e-6 --cache "$cache" \
           --png "$out/variant-b-4ms-smoothed.png" --csv "$out/variant-b-4ms-smoothed.csv" \
           --json "$out/variant-b-4ms-smoothed.json" "$@"; }
  bs --fixed rk4 --steps 5e-8 --adaptive "" --spectrum-png "$out/variant-b-4ms-smoothed-spectrum.png"
  bs --skip-spectrum --fixed rk4,dumka3 --steps 1e-6,2e-6 --adaptive rock4,dumka3 --rtols 1e-2,3e-2,1e-3
  bs --skip-spectrum --from-cache | tee "$out/variant-b-4ms-smoothed.log"
  uptime | tee -a "$out/variant-b-4ms-smoothed.log"
fi
# Session 12: variant (e) with the smoothed pin-sheave friction law over the source's [1, 5] ms (rigid shafts).
if [[ $part == all || $part == w-4ms-smoothed ]]; then
  cache=out/studies/w-4ms-smoothed-cache
  w4s() { nice "$cvtfem" study accuracy-cost "$(e_scene e smoothed)" --skip-spectrum --window 1e-3:5e-3 \
           --sample 1e-6 --repeats 1 --reference DOP853:1e-6 --check dopri78:1e-6 --cache "$cache" \
           --png "$out/variant-e-w-4ms-smoothed.png" --csv "$out/variant-e-w-4ms-smoothed.csv" \
           --json "$out/variant-e-w-4ms-smoothed.json" "$@"; }
  w4s --fixed rk4 --steps 5e-8 --adaptive ""
  w4s --fixed dumka3 --steps 2e-6,3e-6 --adaptive dumka3,rock4 --rtols 3e-2,1e-2
  w4s --from-cache | tee "$out/variant-e-w-4ms-smoothed.log"
  uptime | tee -a "$out/variant-e-w-4ms-smoothed.log"
fi
# Session 10: W-methods with a reused Jacobian (sw24 with jac_every, ros34pw2) against DUMKA3, rock4 and RK4 on variant
# (e), FROM THE QUASI-STATIC START (converged at ratio 0.45 since session 9's iteration budget; the cache keeps the start
# state, so each further process skips the minute of the solve).  First a window of [0.2, 0.4] ms (references DOP853
# and dopri78 at rtol 1e-7), then the source's [1, 5] ms (rtol 1e-6).  Each invocation prints its rows' table (energy
# residual and speed-ups by wall, CPU and RHS-equivalents); the --from-cache call tabulates everything.  The parts
# under one cache may run in parallel shells (start the reference-computing ones first).
if [[ $part == all || $part == w-short ]]; then
  cache=out/studies/w-short-cache
  ws() { nice "$cvtfem" study accuracy-cost "$(e_scene e linear-saturated)" --skip-spectrum --window 2e-4:4e-4 \
           --sample 1e-6 --repeats 1 --reference DOP853:1e-7 --check dopri78:1e-7 --cache "$cache" \
           --png "$out/variant-e-w-short.png" --csv "$out/variant-e-w-short.csv" --json "$out/variant-e-w-short.json" "$@"; }
  ws --fixed rk4 --steps 5e-8,5e-7 --adaptive ""
  ws --fixed dumka3 --steps 1e-6,2e-6 --adaptive rock4 --rtols 1e-2,1e-3
  ws --fixed "" --adaptive dumka3 --rtols 1e-1,3e-2,1e-2
  ws --fixed sw24,sw24:jac_every=10,sw24:jac_every=20 --steps 2e-6 --adaptive ""
  ws --fixed sw24:jac_every=20,sw24:jac_every=100 --steps 5e-7,1e-6 --adaptive ""
  ws --fixed ros34pw2,ros34pw2:jac_every=5 --steps 1e-6,2e-6 --adaptive ""
  ws --fixed rodas4 --steps 2e-6,4e-6 --adaptive ""
  ws --from-cache | tee "$out/variant-e-w-short.log"
  uptime | tee -a "$out/variant-e-w-short.log"
fi
if [[ $part == all || $part == w-4ms ]]; then
  cache=out/studies/w-4ms-cache
  w4() { nice "$cvtfem" study accuracy-cost "$(e_scene e linear-saturated)" --skip-spectrum --window 1e-3:5e-3 \
           --sample 1e-6 --repeats 1 --reference DOP853:1e-6 --check dopri78:1e-6 --cache "$cache" \
           --png "$out/variant-e-w-4ms.png" --csv "$out/variant-e-w-4ms.csv" --json "$out/variant-e-w-4ms.json" "$@"; }
  w4 --fixed rk4 --steps 5e-8 --adaptive ""             # the baseline (and, in a second shell, the next line)
  w4 --fixed dumka3 --steps 2e-6,1e-6 --adaptive ""
  w4 --fixed sw24:jac_every=20 --steps 5e-7,1e-6 --adaptive ""
  w4 --fixed rk4 --steps 5e-7,1e-6 --adaptive ""
  w4 --fixed "" --adaptive rock4 --rtols 1e-3,1e-2
  w4 --fixed "" --adaptive dumka3 --rtols 1e-1,3e-2,1e-2
  w4 --from-cache | tee "$out/variant-e-w-4ms.log"
  uptime | tee -a "$out/variant-e-w-4ms.log"
  nice .venv/bin/python studies/accuracy-cost/force_trace.py "$out/variant-e-w-4ms.json" "$cache" \
    rk4:5e-7,sw24:jac_every=20:5e-7,dumka3:2e-6 "$out/variant-e-w-4ms-trace.png" | tee -a "$out/variant-e-w-4ms.log"
fi
if [[ $part == all || $part == variant-e || $part == variant-e-spectra ]]; then   # which friction is stiffest
  for v in e zh; do
    nice .venv/bin/python studies/accuracy-cost/a5_friction_spectra.py "$(e_scene $v linear-saturated)" \
      "$out/variant-$v-linear-saturated-friction-spectra.png" | tee "$out/variant-$v-linear-saturated-friction-spectra.log"
  done
fi
# Session 11: the halves' internal friction (axial (1.221) and rolling) split off and solved implicitly (strang-friction:
# Strang splitting, or the friction forces of a backward-Euler step held over an explicit DUMKA3/RK4 step), on the
# short window of w-short (same cache: its references and start).  The friction owners at 0.2 ms come from
# a5_friction_owners.py.
# Session 11: DUMKA3 at a fixed 3e-6 s over [1, 5] ms (accepted on the short window, 9.9x over RK4 there), beside
# 2e-6 s and the RK4 baseline, in a cache of its own (the session-10 rows of w-4ms stay as they are).
if [[ $part == all || $part == w-4ms-dumka3 ]]; then
  cache=out/studies/w-4ms-dumka3-cache
  wd() { nice "$cvtfem" study accuracy-cost "$(e_scene e linear-saturated)" --skip-spectrum --window 1e-3:5e-3 \
           --sample 1e-6 --repeats 1 --reference DOP853:1e-6 --check dopri78:1e-6 --cache "$cache" \
           --png "$out/variant-e-w-4ms-dumka3.png" --csv "$out/variant-e-w-4ms-dumka3.csv" \
           --json "$out/variant-e-w-4ms-dumka3.json" "$@"; }
  wd --fixed rk4 --steps 5e-8 --adaptive ""
  wd --fixed dumka3 --steps 2e-6,3e-6 --adaptive ""
  wd --from-cache | tee "$out/variant-e-w-4ms-dumka3.log"
  uptime | tee -a "$out/variant-e-w-4ms-dumka3.log"
fi
if [[ $part == all || $part == imex-short ]]; then
  cache=out/studies/w-short-cache
  is() { nice "$cvtfem" study accuracy-cost "$(e_scene e linear-saturated)" --skip-spectrum --window 2e-4:4e-4 \
           --sample 1e-6 --repeats 1 --reference DOP853:1e-7 --check dopri78:1e-7 --cache "$cache" \
           --csv "$out/variant-e-imex-short.csv" --json "$out/variant-e-imex-short.json" "$@"; }
  nice .venv/bin/python studies/accuracy-cost/a5_friction_owners.py "$cache" 2e-4 | tee "$out/variant-e-friction-owners.log"
  is --fixed strang-friction,strang-friction:scheme=frozen,strang-friction:scheme=frozen-mid --steps 1e-6,2e-6 \
    --adaptive ""
  is --fixed strang-friction:scheme=frozen-mid,dumka3 --steps 2.5e-6,3e-6 --adaptive ""
  is --fixed strang-friction:scheme=frozen-mid:explicit=rk4 --steps 4e-7 --adaptive ""
  is --fixed dumka3 --steps 1e-6,2e-6 --adaptive ""
  is --from-cache | tee "$out/variant-e-imex-short.log"
  uptime | tee -a "$out/variant-e-imex-short.log"
fi
# Session 12: all friction of (e) implicit (the split variant "all": the halves' and the pin-sheave friction in f_I),
# RK4 on f_E (its radius 1.37e6 1/s without any friction: a5_all_friction_radius.py), coupled by the IMEX schemes
# imex-rk4 / imex-rk4-2 (order 2) or by frozen-mid, beside DUMKA3 and the RK4 baseline at 5e-8 s, on the short window
# of w-short (same cache); the friction side's costs per piece from imex_all_costs.py.
if [[ $part == all || $part == imex-all-short ]]; then
  cache=out/studies/w-short-cache
  ia() { nice "$cvtfem" study accuracy-cost "$(e_scene e linear-saturated)" --skip-spectrum --window 2e-4:4e-4 \
           --sample 1e-6 --repeats 1 --reference DOP853:1e-7 --check dopri78:1e-7 --cache "$cache" \
           --png "$out/variant-e-imex-all-short.png" --csv "$out/variant-e-imex-all-short.csv" \
           --json "$out/variant-e-imex-all-short.json" "$@"; }
  nice .venv/bin/python studies/accuracy-cost/a5_all_friction_radius.py "$cache" 2e-4 \
    | tee "$out/variant-e-all-friction-radius.log"
  ia --fixed strang-friction:scheme=imex-rk4:friction=all,strang-friction:scheme=imex-rk4-2:friction=all \
    --steps 1e-6,1.5e-6,2e-6 --adaptive ""
  ia --fixed strang-friction:scheme=imex-rk4:friction=all --steps 2.2e-6 --adaptive ""     # past RK4's limit on f_E
  ia --fixed strang-friction:scheme=frozen-mid:explicit=rk4:friction=all --steps 1e-6,2e-6 --adaptive ""
  ia --fixed dumka3 --steps 2e-6,3e-6 --adaptive ""
  ia --fixed rk4 --steps 5e-8 --adaptive ""
  ia --from-cache | tee "$out/variant-e-imex-all-short.log"
  for scheme in imex-rk4 imex-rk4-2; do
    nice .venv/bin/python studies/accuracy-cost/imex_all_costs.py "$cache" $scheme | tee -a "$out/variant-e-imex-all-short.log"
  done
  uptime | tee -a "$out/variant-e-imex-all-short.log"
fi
for tag in elastic elastic-inclined; do    # (e) on elastic shafts, flat face and the presets' inclined face (session 13)
  if [[ $part == all || $part == elastic-short || $part == "$tag-short" ]]; then
    cache=out/studies/e-$tag-short-cache
    ie() { nice "$cvtfem" study accuracy-cost "studies/accuracy-cost/scenes/variant-e-$tag-chapter2-linear-saturated.toml" \
             --skip-spectrum --window 2e-4:4e-4 --sample 1e-6 --repeats 1 --reference DOP853:1e-7 --check dopri78:1e-7 \
             --cache "$cache" --png "$out/variant-e-$tag-short.png" --csv "$out/variant-e-$tag-short.csv" \
             --json "$out/variant-e-$tag-short.json" "$@"; }
    ie --fixed strang-friction:scheme=imex-rk4:friction=all --steps 1e-6,1.5e-6,2e-6 --adaptive ""
    ie --fixed dumka3 --steps 3e-6 --adaptive dumka3 --rtols 3e-2
    ie --fixed rk4 --steps 5e-8 --adaptive ""
    ie --from-cache | tee "$out/variant-e-$tag-short.log"
    uptime | tee -a "$out/variant-e-$tag-short.log"
    if [[ $tag == elastic-inclined ]]; then   # session 16: the modes an explicit step meets, group by group
      nice .venv/bin/python studies/accuracy-cost/a5_explicit_ladder.py \
        "studies/accuracy-cost/scenes/variant-e-$tag-chapter2-linear-saturated.toml" "$cache" 2e-4 \
        | tee "$out/variant-e-$tag-explicit-ladder.log"
    fi
  fi
done
# Session 14: the source's window [1, 5] ms on (e) as the presets build it (elastic shafts, the inclined face): the
# RK4 baseline, DUMKA3 fixed and the preset's adaptive DUMKA3, imex-rk4 with all friction implicit (about 40 min of one
# core, most of it the two references); session 15: the same with the smoothed pin-sheave law (the study's second law).
for law in linear-saturated smoothed; do
  tag=elastic-inclined-4ms
  if [[ $law == smoothed ]]; then tag+=-smoothed; fi
  if [[ $part == all || $part == "$tag" ]]; then
    cache=out/studies/e-$tag-cache
    e4i() { nice "$cvtfem" study accuracy-cost "studies/accuracy-cost/scenes/variant-e-elastic-inclined-chapter2-$law.toml" \
              --skip-spectrum --window 1e-3:5e-3 --sample 1e-6 --repeats 1 --reference DOP853:1e-6 --check dopri78:1e-6 \
              --cache "$cache" --png "$out/variant-e-$tag.png" --csv "$out/variant-e-$tag.csv" \
              --json "$out/variant-e-$tag.json" "$@"; }
    e4i --fixed rk4 --steps 5e-8 --adaptive ""
    e4i --fixed dumka3 --steps 2e-6,3e-6 --adaptive dumka3 --rtols 3e-2
    e4i --fixed strang-friction:scheme=imex-rk4:friction=all --steps 2e-6 --adaptive ""
    e4i --from-cache | tee "$out/variant-e-$tag.log"
    uptime | tee -a "$out/variant-e-$tag.log"
    # session 16: what the judged output itself asks of a step (the reference rebuilt from every H-th sample)
    .venv/bin/python studies/accuracy-cost/step_floor.py "$out/variant-e-$tag.json" "$cache" \
      | tee "$out/variant-e-$tag-step-floor.log"
  fi
done
# Session 18: multirate-rk4 (all friction integrated by damped Chebyshev stages at frozen positions inside RK4, no
# solve) beside the RK4 baseline and DUMKA3 on the short window and over [1, 5] ms of (e) as the presets build it (the
# caches of elastic-inclined-short and elastic-inclined-4ms: their references and starts), and at the settled
# stationary regime (stationary_rows.py on the newest checkpoint of a stationary run: a copy of it is read).
if [[ $part == all || $part == multirate ]]; then
  mr() { local cache=$1 tag=$2 window=$3 ref=$4; shift 4
    nice "$cvtfem" study accuracy-cost studies/accuracy-cost/scenes/variant-e-elastic-inclined-chapter2-linear-saturated.toml \
      --skip-spectrum --window "$window" --sample 1e-6 --repeats 1 --reference "DOP853:$ref" --check "dopri78:$ref" \
      --cache "$cache" --png "$out/variant-e-$tag.png" --csv "$out/variant-e-$tag.csv" --json "$out/variant-e-$tag.json" "$@"; }
  for w in "out/studies/e-elastic-inclined-short-cache multirate-short 2e-4:4e-4 1e-7" \
           "out/studies/e-elastic-inclined-4ms-cache multirate-4ms 1e-3:5e-3 1e-6"; do
    set -- $w
    mr "$@" --fixed rk4 --steps 5e-8 --adaptive ""
    mr "$@" --fixed dumka3 --steps 2e-6,3e-6 --adaptive dumka3 --rtols 3e-2
    mr "$@" --fixed strang-friction:scheme=multirate-rk4:friction=all --steps 2e-6,1.5e-6 --adaptive ""
    mr "$@" --from-cache | tee "$out/variant-e-$2.log"
    uptime | tee -a "$out/variant-e-$2.log"
  done
  run=out/studies/chain/variant_e_inclined.h5      # `cvtfem run studies/chain/variant-e-stationary-inclined.toml` (0.3 s)
  if [[ -f $run ]]; then
    cp "$run" out/studies/chain/variant_e_inclined_rows.h5
    nice .venv/bin/python studies/accuracy-cost/stationary_rows.py out/studies/chain/variant_e_inclined_rows.h5 \
      | tee "$out/variant-e-stationary-rows.log"
  fi
fi
# Session 19: multirate-rk4 adaptive below its 1.5e-6 s cap (the default of variant-e since then) beside the same
# method at the fixed cap, the former default (DUMKA3 adaptive, rtol 3e-2) and the RK4 baseline over [1, 5] ms of (e)
# as the presets build it (the elastic-inclined-4ms cache: its references and start).
if [[ $part == all || $part == adaptive ]]; then
  ad() { nice "$cvtfem" study accuracy-cost studies/accuracy-cost/scenes/variant-e-elastic-inclined-chapter2-linear-saturated.toml \
      --skip-spectrum --window 1e-3:5e-3 --sample 1e-6 --repeats 1 --reference DOP853:1e-6 --check dopri78:1e-6 \
      --cache out/studies/e-elastic-inclined-4ms-cache --png "$out/variant-e-adaptive-4ms.png" \
      --csv "$out/variant-e-adaptive-4ms.csv" --json "$out/variant-e-adaptive-4ms.json" "$@"; }
  ad --fixed rk4 --steps 5e-8 --adaptive ""
  ad --fixed "" --adaptive dumka3 --rtols 3e-2
  ad --fixed strang-friction:scheme=multirate-rk4:friction=all --steps 1.5e-6 --adaptive ""
  ad --fixed "" --adaptive strang-friction:scheme=multirate-rk4:friction=all:max_step=1.5e-6 --rtols 1e-2,3e-3,1e-3
  ad --from-cache | tee "$out/variant-e-adaptive-4ms.log"
  uptime | tee -a "$out/variant-e-adaptive-4ms.log"
fi
