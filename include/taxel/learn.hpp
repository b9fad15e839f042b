// SPDX-License-Identifier: MIT
// taxel::learn: classifiers (linear SVM, LDA, kNN, RBF SVM, MLP), scalers, cross-validation,
// the 5x2cv paired t test and feature noise.
#pragma once

#include "taxel/learn/concepts.hpp"
#include "taxel/learn/dataset.hpp"
#include "taxel/learn/evaluation.hpp"
#include "taxel/learn/knn.hpp"
#include "taxel/learn/lda.hpp"
#include "taxel/learn/linear_svm.hpp"
#include "taxel/learn/mlp.hpp"
#include "taxel/learn/rbf_svm.hpp"
#include "taxel/learn/scaler.hpp"
#include "taxel/learn/stats.hpp"
