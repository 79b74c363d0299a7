// Atlas view: an Atlas 2.5D cloudscape drawn by @takram/three-clouds.
//
// The scene comes from `atlas view` (scene.js sets window.ATLAS_SCENE; see
// docs/web.md for its fields). Atlas's world is east x, north y, up z in
// metres; it is placed on the WGS84 ellipsoid at latitude 0, longitude 0
// with the map centre at the origin of that point's east-north-up frame.
// There the cube-sphere UV three-clouds tiles its weather texture with is
// u = 1/2 + (east / R) / sqrt(2), v = 1/2 + (north / R) / sqrt(2), so one
// tile of `size` metres is repeat = sqrt(2) R / size (docs/web.md).
//
// URL parameters (the test renders with them): camera=X,Y,Z,LX,LY,LZ,
// fov=DEG, size=WxH, output=color|alpha (alpha: the clouds' opacity as
// grey), frames=N (render N frames, then set window.atlasViewDone), still=1
// (no orbit controls, no temporal upscaling).
import {
  EffectComposer,
  EffectPass,
  RenderPass,
  ShaderPass,
  ToneMappingEffect,
  ToneMappingMode
} from 'postprocessing'
import {
  Data3DTexture,
  HalfFloatType,
  LinearFilter,
  LoadingManager,
  LinearMipMapLinearFilter,
  Matrix4,
  NoColorSpace,
  NearestFilter,
  NoToneMapping,
  PerspectiveCamera,
  RedFormat,
  RepeatWrapping,
  Scene,
  ShaderMaterial,
  TextureLoader,
  UnsignedByteType,
  Uniform,
  Vector3,
  WebGLRenderer
} from 'three'
import { OrbitControls } from 'three/addons/controls/OrbitControls.js'
import {
  AerialPerspectiveEffect,
  PrecomputedTexturesLoader
} from '@takram/three-atmosphere'
import {
  CLOUD_SHAPE_DETAIL_TEXTURE_SIZE,
  CLOUD_SHAPE_TEXTURE_SIZE,
  CloudsEffect
} from '@takram/three-clouds'
import {
  DataTextureLoader,
  Ellipsoid,
  Geodetic,
  parseUint8Array
} from '@takram/three-geospatial'

const scene = window.ATLAS_SCENE
const params = new URLSearchParams(window.location.search)
const status = document.getElementById('status')

function fail(message) {
  status.textContent = message
  status.className = 'error'
  window.atlasViewError = message
  throw new Error(message)
}

function numbers(text, count, name, separator = ',') {
  const v = text.split(separator).map(Number)
  if (v.length !== count || v.some(x => !Number.isFinite(x))) {
    fail(`URL parameter ${name}: expected ${count} numbers separated by '${separator}', got '${text}'`)
  }
  return v
}

if (scene == null) fail('scene.js did not set window.ATLAS_SCENE: open the index.html that atlas view wrote')

// Atlas world (east, north, up; metres from the map centre) to ECEF.
const origin = new Geodetic(0, 0, 0).toECEF()
const enu = Ellipsoid.WGS84.getEastNorthUpFrame(origin)
const centre = scene.map.centre
function toEcef([x, y, z]) {
  return new Vector3(x - centre[0], y - centre[1], z).applyMatrix4(enu)
}

const cam = params.has('camera')
  ? numbers(params.get('camera'), 6, 'camera')
  : [...scene.camera.position, ...scene.camera.look_at]
const fov = params.has('fov') ? numbers(params.get('fov'), 1, 'fov')[0] : scene.camera.fov
const [width, height] = params.has('size')
  ? numbers(params.get('size'), 2, 'size', 'x')
  : [window.innerWidth, window.innerHeight]
const output = params.get('output') ?? 'color'
const still = params.get('still') === '1'
const frames = Number(params.get('frames') ?? 0)

const camera = new PerspectiveCamera(fov, width / height, 10, 1e7)
camera.position.copy(toEcef(cam.slice(0, 3)))
const up = new Vector3(0, 0, 1).transformDirection(enu)
camera.up.copy(up)
const target = toEcef(cam.slice(3, 6))
camera.lookAt(target)

const renderer = new WebGLRenderer({ depth: false, preserveDrawingBuffer: true })
renderer.setPixelRatio(still ? 1 : window.devicePixelRatio)
renderer.setSize(width, height)
renderer.toneMapping = NoToneMapping
renderer.toneMappingExposure = 10 // three-clouds' examples' exposure for its physical radiance
document.body.appendChild(renderer.domElement)

let controls = null
if (!still) {
  controls = new OrbitControls(camera, renderer.domElement)
  controls.enableDamping = true
  controls.target.copy(target)
}

const aerialPerspective = new AerialPerspectiveEffect(camera)
aerialPerspective.sky = true
aerialPerspective.sunLight = true
aerialPerspective.skyLight = true

const clouds = new CloudsEffect(camera)
clouds.qualityPreset = 'high'
clouds.temporalUpscale = !still
clouds.coverage = scene.coverage
clouds.cloudLayers.set(scene.layers)
clouds.localWeatherRepeat.set(scene.weather.repeat[0], scene.weather.repeat[1])
clouds.localWeatherOffset.set(scene.weather.offset[0], scene.weather.offset[1])
clouds.shapeRepeat.set(...scene.shape.repeat)
clouds.shapeOffset.set(...scene.shape.offset)
clouds.shapeDetailRepeat.set(...scene.shape_detail.repeat)
clouds.shapeDetailOffset.set(...scene.shape_detail.offset)
clouds.turbulenceRepeat.set(scene.turbulence.repeat[0], scene.turbulence.repeat[1])
clouds.turbulenceDisplacement = scene.turbulence.displacement
clouds.events.addEventListener('change', event => {
  if (event.property === 'atmosphereOverlay') aerialPerspective.overlay = clouds.atmosphereOverlay
  if (event.property === 'atmosphereShadow') aerialPerspective.shadow = clouds.atmosphereShadow
  if (event.property === 'atmosphereShadowLength') aerialPerspective.shadowLength = clouds.atmosphereShadowLength
})

// Atlas's sun: azimuth 0 = from -y (south), east of south positive.
const az = (scene.sun.azimuth * Math.PI) / 180
const el = (scene.sun.elevation * Math.PI) / 180
const sun = new Vector3(Math.cos(el) * Math.sin(az), -Math.cos(el) * Math.cos(az), Math.sin(el))
  .transformDirection(enu)
aerialPerspective.sunDirection.copy(sun)
clouds.sunDirection.copy(sun)

const composer = new EffectComposer(renderer, { frameBufferType: HalfFloatType, multisampling: 0 })
composer.addPass(new RenderPass(new Scene(), camera))
composer.addPass(new EffectPass(camera, clouds, aerialPerspective))
if (output === 'alpha') {
  // The clouds' own opacity (1 - transmittance) as grey: what the test
  // compares with atlas preview's transmittance.
  composer.addPass(
    new ShaderPass(
      new ShaderMaterial({
        uniforms: { cloudsBuffer: new Uniform(clouds.cloudsPass.outputBuffer) },
        vertexShader: 'varying vec2 vUv; void main() { vUv = position.xy * 0.5 + 0.5; gl_Position = vec4(position.xy, 1.0, 1.0); }',
        fragmentShader: 'uniform sampler2D cloudsBuffer; varying vec2 vUv; void main() { float a = texture2D(cloudsBuffer, vUv).a; gl_FragColor = vec4(vec3(a), 1.0); }'
      })
    )
  )
} else {
  composer.addPass(new EffectPass(camera, new ToneMappingEffect({ mode: ToneMappingMode.AGX })))
}

// three-clouds jitters its ray marches by a spatiotemporal blue-noise volume
// (STBN) it otherwise downloads from GitHub; a page opened offline makes a
// stand-in: interleaved gradient noise (Jimenez 2014), shifted per slice.
function ditherVolume() {
  const w = 128, h = 128, d = 64
  const data = new Uint8Array(w * h * d)
  for (let z = 0; z < d; ++z) {
    for (let y = 0; y < h; ++y) {
      for (let x = 0; x < w; ++x) {
        const px = x + 5.588238 * z, py = y + 5.588238 * z
        const v = (52.9829189 * ((0.06711056 * px + 0.00583715 * py) % 1)) % 1
        data[x + w * (y + h * z)] = Math.floor(v * 256)
      }
    }
  }
  const texture = new Data3DTexture(data, w, h, d)
  texture.type = UnsignedByteType
  texture.format = RedFormat
  texture.minFilter = NearestFilter
  texture.magFilter = NearestFilter
  texture.wrapS = texture.wrapT = texture.wrapR = RepeatWrapping
  texture.needsUpdate = true
  return texture
}

function configure(texture, is3d) {
  texture.minFilter = is3d ? LinearFilter : LinearMipMapLinearFilter
  texture.magFilter = LinearFilter
  texture.wrapS = RepeatWrapping
  texture.wrapT = RepeatWrapping
  if (is3d) {
    texture.wrapR = RepeatWrapping
    texture.format = RedFormat
  }
  texture.colorSpace = NoColorSpace
  texture.needsUpdate = true
  return texture
}

function load2d(url) {
  return new Promise((resolve, reject) => new TextureLoader().load(url, t => resolve(configure(t, false)), undefined, reject))
}

function load3d(url, size) {
  return new Promise((resolve, reject) =>
    new DataTextureLoader(Data3DTexture, parseUint8Array, { width: size, height: size, depth: size }).load(
      url,
      t => resolve(configure(t, true)),
      undefined,
      reject
    )
  )
}

async function start() {
  // The atmosphere's precomputed tables ship with @takram/three-atmosphere;
  // atmosphere.js holds them as data URLs (a page opened from disk may not
  // read files next to it). Computing them here instead takes minutes on a
  // software renderer.
  status.textContent = 'loading the atmosphere...'
  const tables = window.ATLAS_ATMOSPHERE
  if (tables == null) fail('atmosphere.js did not set window.ATLAS_ATMOSPHERE: rebuild plugins/web (npm run build)')
  const manager = new LoadingManager()
  manager.setURLModifier(url => tables[url.split('/').pop()] ?? url)
  const atmosphere = await new Promise((resolve, reject) =>
    new PrecomputedTexturesLoader({ format: 'binary' }, manager).setType(renderer).load('atmosphere', resolve, undefined, reject)
  )
  Object.assign(aerialPerspective, atmosphere)
  Object.assign(clouds, atmosphere)

  status.textContent = 'loading the cloudscape...'
  const t = scene.textures
  const [weather, shape, detail, turbulence] = await Promise.all([
    load2d(t.local_weather),
    load3d(t.shape, CLOUD_SHAPE_TEXTURE_SIZE),
    load3d(t.shape_detail, CLOUD_SHAPE_DETAIL_TEXTURE_SIZE),
    load2d(t.turbulence)
  ]).catch(e => fail(`could not load the cloudscape's textures: ${e?.message ?? e}`))
  clouds.localWeatherTexture = weather
  clouds.shapeTexture = shape
  clouds.shapeDetailTexture = detail
  clouds.turbulenceTexture = turbulence
  const dither = ditherVolume()
  clouds.stbnTexture = dither
  aerialPerspective.stbnTexture = dither
  status.textContent = (scene.title ?? '') + (still ? '' : ' | drag: orbit, right-drag: pan, wheel: zoom')

  let frame = 0
  renderer.setAnimationLoop(() => {
    controls?.update()
    composer.render()
    ++frame
    if (frames > 0 && frame >= frames) {
      renderer.setAnimationLoop(null)
      window.atlasViewDone = true
    }
  })
}

start().catch(e => fail(String(e?.message ?? e)))
