// Wires the archgram client together: one editor, its services, its views.
import { Editor } from './editor.js';
import { Api } from './api.js';
import { Live } from './live.js';
import { Session } from './session.js';
import { Upload } from './upload.js';
import { Viewport } from './viewport.js';
import { Toolbar } from './toolbar.js';
import { ModelsPanel } from './models.js';
import { Inspector } from './inspector.js';
import { PeersPanel } from './peers.js';
import { HistoryPanel } from './history.js';
import { Toast } from './toast.js';
import { Procedural } from './procedural.js';
import { SplitTreePanel } from './treepanel.js';
import { GrammarPanel } from './grammarpanel.js';
import { collapsible } from './collapse.js';
import { Extrusion } from './extrusion.js';
import { PlanEditor } from './planeditor.js';
import { PlanFeatures } from './planfeatures.js';
import { ProfileEditor } from './profileeditor.js';
import { CityView, NewExtrusionPanel } from './cityview.js';
import { PreviewLayer } from './previewlayer.js';
import { EditTools } from './edittools.js';
import { Handles } from './handles.js';
import { Undo } from './undo.js';
import { Auth } from './auth.js';
import { ShareDialog } from './share.js';
import { WindowSelect } from './windowselect.js';
import { TreeWalk } from './treewalk.js';
import { LibraryPanel } from './librarypanel.js';
import { NodeInfo } from './nodeinfo.js';
import { CloudView } from './cloudview.js';
import { CloudPanel } from './cloudpanel.js';

const $ = (id) => document.getElementById(id);
const editor = new Editor();
const api = new Api();
const auth = new Auth(editor, api, $('overlays'));
const share = new ShareDialog(editor, api, $('overlays'));
const live = new Live(editor, api);
editor.useTransport(live); // editor.execute sends every op through the live connection
const session = new Session(editor, api, live);
const upload = new Upload(editor, api, live, session);
const procedural = new Procedural(editor, api, live);

new Toast(editor, $('toasts'));
new Toolbar(editor, session, $('toolbar'), { auth, share });
new ModelsPanel(editor, session, upload, $('models'));
const viewport = new Viewport(editor, api, $('viewport'));
const preview = new PreviewLayer(editor, viewport, live);
const editTools = new EditTools(editor, api, viewport, $('edit'));
const handles = new Handles(editor, viewport, live, preview, editTools);
new Undo(editor, editTools.undoSlot);
new Inspector(editor, $('inspector'));
new Extrusion(editor, api, viewport);
new NewExtrusionPanel(editor, upload, $('extrude-new'));
new PlanEditor(editor, $('plan-pane'));
new PlanFeatures(editor, $('plan-edits'));
new ProfileEditor(editor, $('profile-pane'));
new CityView(editor, viewport, $('city'));
new PeersPanel(editor, $('peers'));
new HistoryPanel(editor, session, $('history'));
new SplitTreePanel(editor, procedural, $('tree'));
const windowSelect = new WindowSelect(editor, viewport);
const walk = new TreeWalk(editor);
new NodeInfo(editor, viewport);
const cloudView = new CloudView(editor, viewport);
new CloudPanel(editor, api, live, $('points'));
const library = new LibraryPanel(editor, api, viewport, windowSelect, $('library'));
new GrammarPanel(editor, procedural, $('grammar'));
collapsible(document.querySelectorAll('section[id]'));

// Viewers see the extrusion panes without their tool bars (style.css: [data-read-only]).
const markReadOnly = () => document.body.toggleAttribute('data-read-only', !!editor.model && !editor.canEdit);
editor.signals.roleChanged.add(markReadOnly);
editor.signals.modelOpened.add(markReadOnly);

window.addEventListener('unhandledrejection', (e) => {
  editor.fail(e.reason);
});

window.archgram = editor; // for poking at state from the console
window.archgramAuth = auth;
window.archgramTools = { viewport, preview, editTools, handles, windowSelect, walk, library, cloudView }; // and at the edit tools (tests drive handles)

function modelFromHash() {
  const m = /^#model=(\d+)$/.exec(location.hash);
  return m ? Number(m[1]) : null;
}

window.addEventListener('hashchange', () => {
  const id = modelFromHash();
  if (id !== null) session.open(id);
});

editor.openModel(null);
await auth.start(); // the sign-in link, the kept token, or the sign-in form
await session.loadModels();
const initial = modelFromHash();
if (initial !== null) await session.open(initial);
