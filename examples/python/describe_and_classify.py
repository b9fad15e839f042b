#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Describes synthetic palm pressure images (segmentation, high-pressure regions, region
descriptors), classifies their grasps with a linear SVM under subject-wise cross-validation, and
compares it with an RBF SVM by the 5x2cv paired t test.

    python3 examples/python/describe_and_classify.py [--out DIR]
"""
import argparse
import os
import pathlib

import numpy as np

from taxel import image, learn, sim

CLASSES = {1: "planar", 2: "one-edged", 3: "two-edged", 4: "cylindrical"}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=pathlib.Path, default=pathlib.Path("."), help="where the figure goes")
    quick = bool(os.environ.get("TAXEL_EXAMPLE_QUICK"))
    ap.add_argument("--subjects", type=int, default=4 if quick else 10)
    args = ap.parse_args()

    data = sim.PalmGraspSynth(seed=7).dataset(args.subjects, 5)
    images, labels, subjects = data["images"], data["labels"], data["subjects"]
    print(f"{len(images)} images of {images.shape[1]} x {images.shape[2]} tactels, {args.subjects} subjects")

    # One image, step by step.
    seg = image.segment(images[0])
    props = image.regionprops(image.label(seg.high)[0])
    print(f"image 0 ({CLASSES[labels[0]]}): k-means levels {np.round(seg.kmeans.centroids, 1)}, "
          f"{seg.regions} high-pressure regions")
    for p in props:
        print(f"  region {p['label']}: area {p['area']:.0f} px, centroid ({p['centroid'][0]:.1f}, "
              f"{p['centroid'][1]:.1f}), orientation {p['orientation']:.1f} deg, "
              f"eccentricity {p['eccentricity']:.2f}")

    # Every image: the recogniser's regional features, scaled, then a linear SVM; folds keep
    # each subject's images together.
    features = image.Recognizer().features(images)["regional"]
    x = (features - features.mean(axis=0)) / (features.std(axis=0) + 1e-12)
    report = learn.cross_validate(learn.LinearSvm(C=1.0), x, labels, subjects, folds=args.subjects // 2 or 2,
                                  grouped=True)
    print(f"linear SVM, subject-wise cross-validation: accuracy {report.accuracy:.3f}")
    print("confusion (rows true, columns predicted):", *(CLASSES[c] for c in report.classes))
    print(report.confusion)
    test = learn.five_by_two_cv(learn.LinearSvm(), learn.RbfSvm(), x, labels, seed=1)
    print(f"5x2cv linear vs RBF SVM: t = {test.t:.2f}, p = {test.p_value:.3f}, "
          f"{'different' if test.reject else 'no significant difference'} at alpha {test.alpha}")

    import matplotlib

    matplotlib.use(os.environ.get("MPLBACKEND", "Agg"))
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(10, 3.4))
    axes[0].imshow(images[0], cmap="viridis")
    axes[0].set_title("pressure")
    axes[1].imshow(seg.classes, cmap="gray")
    axes[1].set_title("k-means classes (K = 3)")
    axes[2].imshow(image.rec_edgeless(images[0], seg), cmap="magma")
    axes[2].set_title("RecEdgeless height")
    for ax in axes:
        ax.set_axis_off()
    out = args.out / "palm_image.png"
    fig.savefig(out, dpi=110, bbox_inches="tight")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
