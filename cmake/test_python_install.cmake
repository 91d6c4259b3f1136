# Test driver: install the Python package (component "python") from BUILD_DIR into a scratch
# prefix and use it from there, away from the build tree: import, a decomposition, a model file.
set(prefix ${BUILD_DIR}/test-install-python)
file(REMOVE_RECURSE ${prefix})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix} --component python
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(rc)
  message(FATAL_ERROR "install failed: ${rc}")
endif()
set(site ${prefix}/${SITE_DIR})
if(NOT EXISTS ${site}/gyrodrift/__init__.py OR NOT EXISTS ${site}/gyrodrift/__init__.pyi)
  message(FATAL_ERROR "the package is not in ${site}")
endif()
execute_process(
  COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${site} PYTHONDONTWRITEBYTECODE=1
          ${PYTHON} -c "import gyrodrift as gd, numpy as np, os, sys; assert os.path.dirname(gd.__file__) == os.path.join(sys.argv[1], 'gyrodrift'), gd.__file__; imfs, residue, report = gd.decompose(np.sin(np.arange(512.0) / 5) + np.arange(512.0) / 100, method='emd'); assert np.allclose(imfs.sum(axis=1) + residue, np.sin(np.arange(512.0) / 5) + np.arange(512.0) / 100); print(gd.__version__, report['summary'])"
          ${site}
  WORKING_DIRECTORY ${prefix}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "${out}")
if(rc)
  message(FATAL_ERROR "the installed package failed:\n${out}\n${err}")
endif()
