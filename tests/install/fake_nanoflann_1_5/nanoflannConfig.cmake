# SPDX-License-Identifier: MIT
# Stands in for a nanoflann 1.5 installation in the configure check; never used to build.
add_library(nanoflann::nanoflann INTERFACE IMPORTED)
