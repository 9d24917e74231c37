# Draws docs/figures/overview.png (the README's picture) from one run of
# experiments/thesis-retro.toml: the searched 2-texture factorization's two
# texture previews and its sphere render (original | approximation | error).
#
#   ./build/experiments/brdf-factor run experiments/thesis-retro.toml --out results/thesis-retro
#   python3 docs/figures/overview.py results/thesis-retro/runs/<search run_id> docs/figures/overview.png
#
# Needs matplotlib (scripts/install-deps.sh installs Debian's python3-matplotlib).
import json, sys
import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt
import matplotlib.image as mpimg
run = sys.argv[1]; out = sys.argv[2]
j = json.load(open(run + '/factors.json'))
t0 = mpimg.imread(run + '/factors_term0.png'); t1 = mpimg.imread(run + '/factors_term1.png')
sph = mpimg.imread(run + '/sphere.png')
fig = plt.figure(figsize=(10.5, 2.9), dpi=110)
gs = fig.add_gridspec(1, 3, width_ratios=[1, 1, 3.05], wspace=0.08)
for k, (img, t) in enumerate([(t0, j['terms'][0]), (t1, j['terms'][1])]):
    ax = fig.add_subplot(gs[0, k]); ax.imshow(img, interpolation='nearest'); ax.set_xticks([]); ax.set_yticks([])
    m = t['matrix']
    ax.set_title('texture %d (%dx%d)' % (k, t['resolution'], t['resolution']), fontsize=9)
    ax.set_xlabel('read through a searched\n2D projection of (wi, wo)', fontsize=7)
ax = fig.add_subplot(gs[0, 2]); ax.imshow(sph); ax.set_xticks([]); ax.set_yticks([])
ax.set_title('original BRDF  |  2-texture approximation  |  error', fontsize=9)
ax.set_xlabel('bluepaint (pbrt-v1 Lafortune), light next to the camera: the retro-reflective rim is kept', fontsize=7)
fig.savefig(out, bbox_inches='tight', facecolor='white')
