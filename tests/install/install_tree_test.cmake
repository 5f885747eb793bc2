# ctest install.tree: installs the build into a temporary prefix outside the source and build
# trees, runs the installed glint from there (its version report, then synth + classify with the
# default model, which it must find under the prefix) and builds examples/cpp against the
# installed CMake package.
#   cmake -DBUILD_DIR=build/release -DSOURCE_DIR=. [-DLIBRARY_CXX_FLAGS=... -DLIBRARY_LINKER_FLAGS=...]
#         -P tests/install/install_tree_test.cmake
cmake_minimum_required(VERSION 3.25)

string(RANDOM LENGTH 8 suffix)
set(work /tmp/glint-install-test-${suffix})
set(prefix ${work}/prefix)
file(REMOVE_RECURSE ${work})
file(MAKE_DIRECTORY ${work})

# Runs a command in ${work} with no glint environment overrides; fails the test on a non-zero
# exit. The output is left in `output`.
function(run)
  execute_process(
    COMMAND ${CMAKE_COMMAND} -E env --unset=GLINT_MODELS_DIR --unset=GLINT_MODELS
            --unset=GLINT_PLUGIN_DIR --unset=GLINT_WEB_DIR --unset=GLINT_TRAIN_PLUGIN
            --unset=GLINT_DENOISE_PLUGIN --unset=GLINT_HEMICNN_PLUGIN ${ARGN}
    WORKING_DIRECTORY ${work} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "failed (${status}): ${ARGN}\n${out}")
  endif()
  set(output "${out}" PARENT_SCOPE)
endfunction()

function(expect text)
  string(FIND "${output}" "${text}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "expected '${text}' in:\n${output}")
  endif()
endfunction()

run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
foreach(file bin/glint lib/glint/edges-train.so share/glint/models/bounded-3c.json
        include/glint/edges/features.h lib/cmake/glint/glintConfig.cmake
        lib/cmake/glint/glintConfigVersion.cmake lib/cmake/glint/glintTargets.cmake)
  if(NOT EXISTS ${prefix}/${file})
    message(FATAL_ERROR "not installed: ${prefix}/${file}")
  endif()
endforeach()

run(${prefix}/bin/glint --version)
expect("models: ${prefix}/share/glint/models")
expect("plugins: ${prefix}/lib/glint")
expect("viewer page: ${prefix}/share/glint/web")
# The viewer's three.js modules are installed where web/node_modules was there when CMake ran.
if(EXISTS ${SOURCE_DIR}/web/node_modules/three/package.json)
  foreach(file index.html viewer.js three/three.module.min.js three/addons/loaders/GLTFLoader.js)
    if(NOT EXISTS ${prefix}/share/glint/web/${file} OR IS_SYMLINK ${prefix}/share/glint/web/${file})
      message(FATAL_ERROR "not installed as a file: ${prefix}/share/glint/web/${file}")
    endif()
  endforeach()
endif()
message(STATUS "${output}")

run(${prefix}/bin/glint --quiet edges synth -o clouds --count 1 --seed 4 --min-points 1500
    --max-points 2000 --shapes box)
file(GLOB cloud ${work}/clouds/*.ply)
run(${prefix}/bin/glint edges classify ${cloud} -o labelled.ply --report report.json --quiet)
file(READ ${work}/report.json report)
string(JSON model GET "${report}" model)
if(NOT model STREQUAL "${prefix}/share/glint/models/bounded-3c.json")
  message(FATAL_ERROR "the installed glint used the model ${model}")
endif()
message(STATUS "${output}")

# The example is compiled with the flags the installed libraries were (a sanitizer build's
# libraries need its runtime linked in).
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/cpp -B example -DCMAKE_PREFIX_PATH=${prefix}
    -DCMAKE_BUILD_TYPE=Release "-DCMAKE_CXX_FLAGS=${LIBRARY_CXX_FLAGS}"
    "-DCMAKE_EXE_LINKER_FLAGS=${LIBRARY_LINKER_FLAGS}")
run(${CMAKE_COMMAND} --build example)
run(example/classify_cloud ${cloud} example.ply)
expect("points:")
message(STATUS "${output}")

file(REMOVE_RECURSE ${work})
