# SPDX-License-Identifier: MIT
# Peer libraries used as test oracles and benchmark baselines, never by the library itself:
# LIBLINEAR (Debian liblinear-dev) and LIBSVM (libsvm-dev). Each found one becomes an imported
# target taxel_peer::<name>; TAXEL_PEER_<NAME>_FOUND says whether it exists.

function(taxel_find_peer name header library)
  string(TOUPPER "${name}" _up)
  find_path(TAXEL_PEER_${_up}_INCLUDE ${header})
  find_library(TAXEL_PEER_${_up}_LIBRARY ${library})
  if(TAXEL_PEER_${_up}_INCLUDE AND TAXEL_PEER_${_up}_LIBRARY AND NOT TARGET taxel_peer::${name})
    add_library(taxel_peer::${name} UNKNOWN IMPORTED GLOBAL)
    set_target_properties(taxel_peer::${name} PROPERTIES
      IMPORTED_LOCATION "${TAXEL_PEER_${_up}_LIBRARY}"
      INTERFACE_INCLUDE_DIRECTORIES "${TAXEL_PEER_${_up}_INCLUDE}")
  endif()
  if(TARGET taxel_peer::${name})
    set(TAXEL_PEER_${_up}_FOUND TRUE PARENT_SCOPE)
  else()
    set(TAXEL_PEER_${_up}_FOUND FALSE PARENT_SCOPE)
  endif()
endfunction()

taxel_find_peer(liblinear linear.h linear)
taxel_find_peer(libsvm libsvm/svm.h svm)
