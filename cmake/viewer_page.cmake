# The viewer page of `glint view` (core/resources.h web_directory()): web/viewer's page and the
# three.js modules it imports (from web/node_modules/three, installed by scripts/install-deps.sh
# from web/package-lock.json) form share/glint/web: links in the build tree (as the models),
# copies when installed. The import map in web/viewer/index.html names these same places.
set(glint_three ${PROJECT_SOURCE_DIR}/web/node_modules/three)
# Pairs: source, place under share/glint/web.
set(glint_page_files
  ${PROJECT_SOURCE_DIR}/web/viewer/index.html index.html
  ${PROJECT_SOURCE_DIR}/web/viewer/viewer.js viewer.js
  ${glint_three}/LICENSE three/LICENSE
  ${glint_three}/build/three.module.min.js three/three.module.min.js
  ${glint_three}/build/three.core.min.js three/three.core.min.js
  ${glint_three}/examples/jsm/loaders/GLTFLoader.js three/addons/loaders/GLTFLoader.js
  ${glint_three}/examples/jsm/utils/BufferGeometryUtils.js three/addons/utils/BufferGeometryUtils.js
  ${glint_three}/examples/jsm/controls/OrbitControls.js three/addons/controls/OrbitControls.js
  ${glint_three}/examples/jsm/controls/TransformControls.js
  three/addons/controls/TransformControls.js)

if(NOT EXISTS ${glint_three}/package.json)
  message(WARNING "web/node_modules/three is missing: `glint view` will not find the three.js "
                  "modules (run scripts/install-deps.sh, then cmake again)")
endif()
set(glint_web_build ${PROJECT_BINARY_DIR}/share/glint/web)
file(REMOVE_RECURSE ${glint_web_build})
list(LENGTH glint_page_files count)
math(EXPR last "${count} - 1")
foreach(i RANGE 0 ${last} 2)
  math(EXPR j "${i} + 1")
  list(GET glint_page_files ${i} source)
  list(GET glint_page_files ${j} place)
  get_filename_component(folder ${place} DIRECTORY)
  file(MAKE_DIRECTORY ${glint_web_build}/${folder})
  if(EXISTS ${source})
    file(CREATE_LINK ${source} ${glint_web_build}/${place} SYMBOLIC)
    get_filename_component(name ${place} NAME)
    install(FILES ${source} DESTINATION ${GLINT_INSTALL_WEBDIR}/${folder} RENAME ${name}
            COMPONENT runtime)
  endif()
endforeach()
