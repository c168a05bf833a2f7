// The TADSL extension: starts `tadslc lsp` for TAD files and YAML scenario answers, passes
// the `tadsl.*` settings to it, and shows each scenario's completeness class.
import * as vscode from "vscode";
import {
  LanguageClient,
  LanguageClientOptions,
  ServerOptions,
  State,
  TransportKind,
} from "vscode-languageclient/node";

let client: LanguageClient | undefined;
let status: vscode.StatusBarItem | undefined;
const classes = new Map<string, string | null>();

/** The checker's settings, as the server reads them (spec/lsp.md). */
function settings(): object {
  const config = vscode.workspace.getConfiguration("tadsl");
  return {
    tadsl: {
      profile: config.get<string>("profile", "auto"),
      region: config.get<string | null>("region", null),
      nonScenario: config.get<string[]>("nonScenario", ["weather", "time", "road"]),
    },
  };
}

function showClass(editor: vscode.TextEditor | undefined): void {
  if (!status) {
    return;
  }
  const found = editor ? classes.get(editor.document.uri.toString()) : undefined;
  if (found) {
    status.text = `TAD: ${found.replace("_", " ")}`;
    status.tooltip = "The scenario's completeness class (tadslc check)";
    status.show();
  } else {
    status.hide();
  }
}

async function start(context: vscode.ExtensionContext, output: vscode.OutputChannel): Promise<void> {
  const config = vscode.workspace.getConfiguration("tadsl");
  const command = config.get<string>("server.path", "tadslc") || "tadslc";
  const args = ["lsp", ...config.get<string[]>("server.extraArgs", [])];
  const serverOptions: ServerOptions = {
    run: { command, args, transport: TransportKind.stdio },
    debug: { command, args, transport: TransportKind.stdio },
  };
  const clientOptions: LanguageClientOptions = {
    documentSelector: [
      { language: "tad" },
      { language: "yaml" },
    ],
    initializationOptions: settings(),
    synchronize: { configurationSection: "tadsl" },
    outputChannel: output,
  };
  client = new LanguageClient("tadsl", "TADSL", serverOptions, clientOptions);
  client.onDidChangeState((event) => {
    if (event.newState === State.Stopped) {
      classes.clear();
      showClass(vscode.window.activeTextEditor);
    }
  });
  try {
    await client.start();
  } catch (error) {
    const message =
      `TADSL: could not start \`${command} lsp\` (${error}). ` +
      "Install tadslc (`cargo install --path compiler/tadslc`) or set `tadsl.server.path`.";
    void vscode.window.showErrorMessage(message, "Open settings").then((choice) => {
      if (choice) {
        void vscode.commands.executeCommand("workbench.action.openSettings", "tadsl.server.path");
      }
    });
    client = undefined;
    return;
  }
  context.subscriptions.push(
    client.onNotification("tadsl/scenarioClass", (params: { uri: string; class: string | null }) => {
      classes.set(params.uri, params.class);
      showClass(vscode.window.activeTextEditor);
    }),
  );
}

export async function activate(context: vscode.ExtensionContext): Promise<void> {
  const output = vscode.window.createOutputChannel("TADSL");
  status = vscode.window.createStatusBarItem(vscode.StatusBarAlignment.Left, 10);
  context.subscriptions.push(
    output,
    status,
    vscode.window.onDidChangeActiveTextEditor(showClass),
    vscode.commands.registerCommand("tadsl.showOutput", () => output.show()),
    vscode.commands.registerCommand("tadsl.restartServer", async () => {
      if (client) {
        await client.stop();
        client = undefined;
      }
      await start(context, output);
    }),
    vscode.workspace.onDidChangeConfiguration(async (event) => {
      if (event.affectsConfiguration("tadsl.server")) {
        await vscode.commands.executeCommand("tadsl.restartServer");
      }
    }),
  );
  await start(context, output);
}

export async function deactivate(): Promise<void> {
  if (client) {
    await client.stop();
  }
}
